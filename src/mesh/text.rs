//! Small nom building blocks shared by the line-oriented mesh readers (OBJ, Candide `.wfm`):
//! an error type that carries what was expected, numbers that must be finite, line ends.

use std::path::Path;

use nom::error::ErrorKind;
use nom::IResult;

use crate::error::ParseError;

/// A nom error: where the parser stopped and what it expected there (empty when a nom
/// built-in failed; [`PErr::located`] then uses the caller's default).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PErr<'a> {
    pub at: &'a str,
    pub expected: &'static str,
}

impl<'a> nom::error::ParseError<&'a str> for PErr<'a> {
    fn from_error_kind(input: &'a str, _kind: ErrorKind) -> Self {
        PErr {
            at: input,
            expected: "",
        }
    }

    fn append(_input: &'a str, _kind: ErrorKind, other: Self) -> Self {
        other
    }
}

impl<'a> PErr<'a> {
    /// Converts into a located [`ParseError`] (`default` when no parser named the expectation).
    pub fn located(&self, file: &Path, text: &str, default: &str) -> ParseError {
        let what = if self.expected.is_empty() {
            default
        } else {
            self.expected
        };
        ParseError::at_rest(file, text, self.at, what)
    }
}

pub(crate) type Res<'a, T> = IResult<&'a str, T, PErr<'a>>;

/// A recoverable error at `at` expecting `what`.
pub(crate) fn fail<'a, T>(at: &'a str, what: &'static str) -> Res<'a, T> {
    Err(nom::Err::Error(PErr { at, expected: what }))
}

/// Spaces and tabs (possibly none).
pub(crate) fn spaces(i: &str) -> Res<'_, &str> {
    let n = i.bytes().take_while(|&b| b == b' ' || b == b'\t').count();
    Ok((&i[n..], &i[..n]))
}

/// A decimal number (`-1`, `2.5`, `.5`, `1e-3`) that fits a finite `f32`.
pub(crate) fn real(i: &str) -> Res<'_, f32> {
    let (rest, token) = nom::number::complete::recognize_float::<_, PErr>(i).map_err(|_| {
        nom::Err::Error(PErr {
            at: i,
            expected: "a number",
        })
    })?;
    match token.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok((rest, v)),
        _ => fail(i, "a finite number (within ±3.4e38)"),
    }
}

/// An optionally signed decimal integer that fits `i64`.
pub(crate) fn integer(i: &str) -> Res<'_, i64> {
    let sign = usize::from(i.starts_with(['+', '-']));
    let digits = i[sign..].bytes().take_while(u8::is_ascii_digit).count();
    if digits == 0 {
        return fail(i, "an integer");
    }
    let (token, rest) = i.split_at(sign + digits);
    match token.parse::<i64>() {
        Ok(v) => Ok((rest, v)),
        Err(_) => fail(i, "an integer of at most 18 digits"),
    }
}

/// An unsigned decimal integer that fits `u64`.
pub(crate) fn unsigned(i: &str) -> Res<'_, u64> {
    let digits = i.bytes().take_while(u8::is_ascii_digit).count();
    if digits == 0 {
        return fail(i, "a non-negative integer");
    }
    match i[..digits].parse::<u64>() {
        Ok(v) => Ok((&i[digits..], v)),
        Err(_) => fail(i, "a non-negative integer of at most 19 digits"),
    }
}

/// A line ending (`\n` or `\r\n`) or the end of input.
pub(crate) fn newline_or_eof(i: &str) -> Res<'_, ()> {
    if let Some(r) = i.strip_prefix("\r\n").or_else(|| i.strip_prefix('\n')) {
        Ok((r, ()))
    } else if i.is_empty() {
        Ok((i, ()))
    } else {
        fail(i, "end of line")
    }
}

/// The rest of the current physical line (without its line ending) and the input after it.
pub(crate) fn rest_of_line(i: &str) -> (&str, &str) {
    let end = i.find('\n').unwrap_or(i.len());
    let line = i[..end].strip_suffix('\r').unwrap_or(&i[..end]);
    (line, &i[(end + 1).min(i.len())..])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_accepts_decimal_forms_and_rejects_non_finite() {
        assert_eq!(real("1.5 x"), Ok((" x", 1.5)));
        assert_eq!(real("-.5"), Ok(("", -0.5)));
        assert_eq!(real("+2e3\n"), Ok(("\n", 2000.0)));
        assert_eq!(real("1."), Ok(("", 1.0)));
        assert_eq!(
            real("nan").unwrap_err(),
            nom::Err::Error(PErr {
                at: "nan",
                expected: "a number"
            })
        );
        assert!(real("inf").is_err());
        let e = real("1e39").unwrap_err();
        assert!(matches!(e, nom::Err::Error(PErr { expected, .. }) if expected.contains("finite")));
    }

    #[test]
    fn integers_are_bounded() {
        assert_eq!(integer("-12/"), Ok(("/", -12)));
        assert!(integer("99999999999999999999").is_err());
        assert!(integer("-").is_err());
        assert_eq!(unsigned("113\n"), Ok(("\n", 113)));
        assert!(unsigned("-1").is_err());
    }

    #[test]
    fn line_helpers() {
        assert_eq!(newline_or_eof("\r\nx"), Ok(("x", ())));
        assert_eq!(newline_or_eof(""), Ok(("", ())));
        assert!(newline_or_eof("x").is_err());
        assert_eq!(rest_of_line("ab\r\ncd"), ("ab", "cd"));
        assert_eq!(rest_of_line("ab"), ("ab", ""));
        assert_eq!(spaces(" \t x"), Ok(("x", " \t ")));
    }
}
