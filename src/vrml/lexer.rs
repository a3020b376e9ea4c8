//! Tokens of the VRML97 UTF-8 syntax as small `nom` combinators over `&str`.
//!
//! Every function here has the `nom` signature `fn(&str) -> IResult<&str, T>` and consumes no
//! leading whitespace: callers skip separators with [`ws`] first. The number scanners are
//! written byte by byte because MF arrays of numbers are the hot path of face files (hundreds
//! of thousands of values); they slice the input and parse the slice, never allocating.

use nom::branch::alt;
use nom::bytes::complete::{tag, take_while, take_while1};
use nom::combinator::{opt, recognize, verify};
use nom::error::{Error, ErrorKind};
use nom::{IResult, Parser};

/// Words of the grammar that can never be node type, field, or DEF names.
pub const KEYWORDS: &[&str] = &[
    "DEF",
    "EXTERNPROTO",
    "FALSE",
    "IS",
    "NULL",
    "PROTO",
    "ROUTE",
    "TO",
    "TRUE",
    "USE",
    "eventIn",
    "eventOut",
    "exposedField",
    "field",
];

fn fail<T>(input: &str, kind: ErrorKind) -> IResult<&str, T> {
    Err(nom::Err::Error(Error::new(input, kind)))
}

/// Skips whitespace, commas (a separator in VRML) and `#` comments up to the end of the line.
/// Never fails.
pub fn ws(input: &str) -> IResult<&str, ()> {
    let bytes = input.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b' ' | b'\t' | b'\n' | b'\r' | b',' => i += 1,
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' && bytes[i] != b'\r' {
                    i += 1;
                }
            }
            _ => break,
        }
    }
    Ok((&input[i..], ()))
}

/// The `#VRML V2.0 utf8` header line; anything after it on the same line is ignored (some
/// exporters append their name). A leading UTF-8 byte order mark is tolerated.
pub fn header(input: &str) -> IResult<&str, ()> {
    let input = input.strip_prefix('\u{feff}').unwrap_or(input);
    let (rest, _) = tag("#VRML V2.0 utf8").parse(input)?;
    // The header must end at a word boundary (`utf8x` is another encoding name).
    if rest
        .chars()
        .next()
        .is_some_and(|c| !c.is_whitespace() && c != '#')
    {
        return fail(input, ErrorKind::Tag);
    }
    let (rest, _) = take_while(|c| c != '\n' && c != '\r').parse(rest)?;
    Ok((rest, ()))
}

/// True for characters that may start a VRML97 identifier.
pub fn is_id_first(c: char) -> bool {
    !(c <= ' '
        || c.is_ascii_digit()
        || matches!(
            c,
            '"' | '#' | '\'' | '+' | ',' | '-' | '.' | '[' | '\\' | ']' | '{' | '}' | '\u{7f}'
        ))
}

/// True for characters that may continue a VRML97 identifier (digits, `+` and `-` allowed).
pub fn is_id_rest(c: char) -> bool {
    c.is_ascii_digit() || c == '+' || c == '-' || is_id_first(c)
}

/// A VRML97 identifier (node type, field, DEF or PROTO name); keywords included.
pub fn identifier(input: &str) -> IResult<&str, &str> {
    recognize((take_while1(is_id_first), take_while(is_id_rest))).parse(input)
}

/// An identifier that is not one of [`KEYWORDS`].
pub fn name(input: &str) -> IResult<&str, &str> {
    verify(identifier, |id: &str| !KEYWORDS.contains(&id)).parse(input)
}

/// The keyword `word` as a whole identifier (`DEFx` is not `DEF`).
pub fn keyword<'a>(
    word: &'static str,
) -> impl Parser<&'a str, Output = &'a str, Error = Error<&'a str>> {
    verify(identifier, move |id: &str| id == word)
}

/// `TRUE` or `FALSE`.
pub fn boolean(input: &str) -> IResult<&str, bool> {
    alt((
        keyword("TRUE").map(|_| true),
        keyword("FALSE").map(|_| false),
    ))
    .parse(input)
}

fn digits_end(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && bytes[i].is_ascii_digit() {
        i += 1;
    }
    i
}

/// The text of a decimal number `[+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?`.
pub fn float_text(input: &str) -> IResult<&str, &str> {
    let b = input.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int_end = digits_end(b, i);
    let mut mantissa_digits = int_end - i;
    i = int_end;
    if i < b.len() && b[i] == b'.' {
        let frac_end = digits_end(b, i + 1);
        mantissa_digits += frac_end - (i + 1);
        if mantissa_digits > 0 {
            i = frac_end;
        }
    }
    if mantissa_digits == 0 {
        return fail(input, ErrorKind::Float);
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        let exp_end = digits_end(b, j);
        if exp_end > j {
            i = exp_end;
        }
    }
    Ok((&input[i..], &input[..i]))
}

/// A finite single-precision number (SFFloat and the components of vectors, colours,
/// rotations). Out-of-range values such as `1e99` fail: VRML has no infinities or NaNs.
pub fn float32(input: &str) -> IResult<&str, f32> {
    let (rest, text) = float_text(input)?;
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok((rest, v)),
        _ => fail(input, ErrorKind::Float),
    }
}

/// A finite double-precision number (SFTime).
pub fn float64(input: &str) -> IResult<&str, f64> {
    let (rest, text) = float_text(input)?;
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok((rest, v)),
        _ => fail(input, ErrorKind::Float),
    }
}

/// The text of an integer: `0x` hexadecimal or signed decimal.
pub fn int_text(input: &str) -> IResult<&str, &str> {
    alt((
        recognize((
            alt((tag("0x"), tag("0X"))),
            take_while1(|c: char| c.is_ascii_hexdigit()),
        )),
        recognize((
            opt(alt((tag("+"), tag("-")))),
            take_while1(|c: char| c.is_ascii_digit()),
        )),
    ))
    .parse(input)
}

/// An SFInt32: decimal within the `i32` range, or hexadecimal up to `0xFFFFFFFF` (read as the
/// two's-complement bit pattern, as VRML uses hex for packed pixel values). A number with a
/// fraction or exponent is not an integer.
pub fn int32(input: &str) -> IResult<&str, i32> {
    let (rest, text) = int_text(input)?;
    // `1.5` or `1e3` must not be read as `1` followed by garbage.
    if rest.starts_with(['.', 'e', 'E']) {
        return fail(input, ErrorKind::Digit);
    }
    let value = if let Some(hex) = text.strip_prefix("0x").or(text.strip_prefix("0X")) {
        u32::from_str_radix(hex, 16).ok().map(|v| v as i32)
    } else {
        text.parse::<i32>().ok()
    };
    match value {
        Some(v) => Ok((rest, v)),
        None => fail(input, ErrorKind::Digit),
    }
}

/// A double-quoted string; `\"` and `\\` are escapes, and a backslash before any other
/// character stands for that character. Strings may span lines.
pub fn string(input: &str) -> IResult<&str, String> {
    let Some(body) = input.strip_prefix('"') else {
        return fail(input, ErrorKind::Char);
    };
    let mut out = String::new();
    let mut start = 0;
    let bytes = body.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                out.push_str(&body[start..i]);
                return Ok((&body[i + 1..], out));
            }
            b'\\' => {
                out.push_str(&body[start..i]);
                // The escaped character may be multi-byte: copy it whole.
                match body[i + 1..].chars().next() {
                    Some(c) => {
                        out.push(c);
                        i += 1 + c.len_utf8();
                        start = i;
                    }
                    None => break,
                }
            }
            _ => i += 1,
        }
    }
    fail(input, ErrorKind::Char)
}

/// True when `input` starts with the token after which a node body opens: `{` after
/// optional separators. Used to tell a node (`Foo {`) from the next field name (`foo 1`).
pub fn opens_body(input: &str) -> bool {
    ws(input).map(|(r, _)| r.starts_with('{')).unwrap_or(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ws_skips_commas_and_comments() {
        assert_eq!(ws(" ,\t# c \"x\n 1").unwrap().0, "1");
        assert_eq!(ws("#only").unwrap().0, "");
        assert_eq!(ws("x").unwrap().0, "x");
    }

    #[test]
    fn header_accepts_trailing_text_only_on_its_line() {
        assert_eq!(
            header("#VRML V2.0 utf8 exported\nGroup{}").unwrap().0,
            "\nGroup{}"
        );
        assert_eq!(header("\u{feff}#VRML V2.0 utf8").unwrap().0, "");
        assert!(header("#VRML V1.0 ascii\n").is_err());
        assert!(header("#VRML V2.0 utf16\n").is_err());
        assert!(header("Group {}").is_err());
    }

    #[test]
    fn identifiers_follow_vrml97_rules() {
        assert_eq!(identifier("Head_1-a+b{").unwrap(), ("{", "Head_1-a+b"));
        assert_eq!(identifier("a.b").unwrap(), (".b", "a"));
        assert_eq!(identifier("été x").unwrap(), (" x", "été"));
        assert!(identifier("1a").is_err());
        assert!(identifier("-a").is_err());
        assert!(identifier("\"a").is_err());
        assert!(name("USE").is_err());
        assert_eq!(name("USEful").unwrap().1, "USEful");
        assert_eq!(keyword("DEF").parse("DEF x").unwrap().0, " x");
        assert!(keyword("DEF").parse("DEFx").is_err());
    }

    #[test]
    fn booleans() {
        assert_eq!(boolean("TRUE ").unwrap(), (" ", true));
        assert_eq!(boolean("FALSE").unwrap(), ("", false));
        assert!(boolean("TRUEX").is_err());
        assert!(boolean("true").is_err());
    }

    #[test]
    fn floats() {
        assert_eq!(float32("1.5 2").unwrap(), (" 2", 1.5));
        assert_eq!(float32("-.5,").unwrap(), (",", -0.5));
        assert_eq!(float32("+2.").unwrap(), ("", 2.0));
        assert_eq!(float32("1e3]").unwrap(), ("]", 1000.0));
        assert_eq!(float32("1.5E-2").unwrap().1, 0.015);
        assert_eq!(float32("3e").unwrap(), ("e", 3.0));
        assert!(float32(".").is_err());
        assert!(float32("-").is_err());
        assert!(float32("nan").is_err());
        assert!(float32("inf").is_err());
        assert!(float32("1e39").is_err(), "overflows f32");
        assert!(float64("1e400").is_err());
        assert_eq!(float64("1e300").unwrap().1, 1e300);
    }

    #[test]
    fn integers() {
        assert_eq!(int32("-12 ").unwrap(), (" ", -12));
        assert_eq!(int32("+7").unwrap().1, 7);
        assert_eq!(int32("0xFF").unwrap().1, 255);
        assert_eq!(int32("0xFFFFFFFF").unwrap().1, -1);
        assert!(int32("2147483648").is_err());
        assert_eq!(int32("-2147483648").unwrap().1, i32::MIN);
        assert!(int32("1.5").is_err());
        assert!(int32("1e3").is_err());
        assert!(int32("x").is_err());
    }

    #[test]
    fn strings_with_escapes() {
        assert_eq!(
            string(r#""a\"b\\c" x"#).unwrap(),
            (" x", "a\"b\\c".to_string())
        );
        assert_eq!(string("\"two\nlines\"").unwrap().1, "two\nlines");
        assert_eq!(string(r#""\é""#).unwrap().1, "é");
        assert_eq!(string("\"# not a comment\"").unwrap().1, "# not a comment");
        assert!(string("\"open").is_err());
        assert!(string("\"ends in \\").is_err());
        assert!(string("x").is_err());
    }

    #[test]
    fn body_lookahead() {
        assert!(opens_body(" # c\n {"));
        assert!(!opens_body(" 1"));
    }
}
