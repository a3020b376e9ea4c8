//! The in-memory model of a FAP stream: header fields plus one [`FapFrame`] per transmitted
//! frame. A frame stores only what was transmitted (its mask says which FAPs); the values held
//! between transmissions are computed by [`crate::fap::timeline`].

use std::fmt;
use std::str::FromStr;

use serde::de::Error as _;
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::spec::{Expression, FapId, Viseme, NUM_FAPS};

/// Number of low-level FAPs (3..=68).
pub const NUM_LOW_LEVEL: usize = NUM_FAPS - 2;

/// The version written when a stream does not name one (Xface, Greta and HMI write `2.1`).
pub const DEFAULT_VERSION: &str = "2.1";

/// Largest FAP value magnitude read (in FAPU; a wide-open jaw is about 1024). Beyond it a
/// value is an input error: a FAPU times 1e39 overflows the `f32` of glTF weights and meshes.
pub const MAX_ABS_FAP_VALUE: f64 = 1e9;

/// Highest stream frame rate read (fps). Faster rates make frame times that `f32` glTF
/// keys cannot tell apart (1e39 fps puts every key at 0 s).
pub const MAX_FRAME_RATE: f64 = 1000.0;

/// A whole ASCII FAP stream.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FapStream {
    /// Format version from the header, e.g. `2.1` (kept as written).
    pub version: String,
    /// Free-text name from the header (Xface writes a Windows path here).
    pub name: String,
    /// Frames per second; finite and > 0 in a valid stream.
    pub frame_rate: f64,
    /// The transmitted frames, frame numbers strictly increasing.
    pub frames: Vec<FapFrame>,
}

impl FapStream {
    /// An empty stream with the default version.
    pub fn new(name: impl Into<String>, frame_rate: f64) -> FapStream {
        FapStream {
            version: DEFAULT_VERSION.to_string(),
            name: name.into(),
            frame_rate,
            frames: Vec::new(),
        }
    }

    /// Time of frame number `n` in seconds (`n / frame_rate`).
    pub fn time_of(&self, n: u64) -> f64 {
        n as f64 / self.frame_rate
    }

    /// Every problem of [`FapStream::structural_problems`] and [`FapStream::value_problems`].
    pub fn problems(&self) -> Vec<String> {
        let mut out = self.structural_problems();
        out.extend(self.value_problems());
        out
    }

    /// Problems that make the stream unplayable: a frame rate that is not finite and
    /// positive, or frame numbers that do not strictly increase.
    pub fn structural_problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !(self.frame_rate.is_finite()
            && self.frame_rate > 0.0
            && self.frame_rate <= MAX_FRAME_RATE)
        {
            out.push(format!(
                "frame rate {} is not a number in (0, {MAX_FRAME_RATE}]",
                self.frame_rate
            ));
        }
        for w in self.frames.windows(2) {
            if w[1].number <= w[0].number {
                out.push(format!(
                    "frame number {} does not increase (previous {})",
                    w[1].number, w[0].number
                ));
            }
        }
        out
    }

    /// Values the standard does not allow: non-finite values and negative values of
    /// unidirectional FAPs.
    pub fn value_problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        for f in &self.frames {
            for (id, v) in f.low_level() {
                if !id.info().accepts(v) {
                    out.push(format!(
                        "frame {}: FAP {id} ({}) = {v} is not allowed",
                        f.number,
                        id.name()
                    ));
                }
            }
        }
        out
    }
}

/// The set of FAPs present in a frame: bit `k` stands for FAP `k + 1` (68 bits used).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FapMask(u128);

const MASK_BITS: u128 = (1u128 << NUM_FAPS) - 1;
/// Bits of FAPs 3..=68.
const LOW_LEVEL_BITS: u128 = MASK_BITS & !0b11;

impl FapMask {
    /// No FAP present.
    pub const EMPTY: FapMask = FapMask(0);

    /// The mask from raw bits (bits above 67 are dropped).
    pub const fn from_bits(bits: u128) -> FapMask {
        FapMask(bits & MASK_BITS)
    }

    /// Raw bits (bit 0 = FAP 1).
    pub const fn bits(self) -> u128 {
        self.0
    }

    /// Whether `fap` is present.
    pub const fn contains(self, fap: FapId) -> bool {
        self.0 & (1u128 << fap.index()) != 0
    }

    /// Adds `fap`.
    pub fn insert(&mut self, fap: FapId) {
        self.0 |= 1u128 << fap.index();
    }

    /// Removes `fap`.
    pub fn remove(&mut self, fap: FapId) {
        self.0 &= !(1u128 << fap.index());
    }

    /// Number of FAPs present.
    pub const fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// True when no FAP is present.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Number of low-level FAPs (3..=68) present.
    pub const fn low_level_len(self) -> usize {
        (self.0 & LOW_LEVEL_BITS).count_ones() as usize
    }

    /// Position of `fap`'s value among the low-level values present (`None` if absent or
    /// high-level): the number of low-level FAPs present below it.
    pub const fn low_level_position(self, fap: FapId) -> Option<usize> {
        if fap.is_high_level() || !self.contains(fap) {
            return None;
        }
        let below = self.0 & LOW_LEVEL_BITS & ((1u128 << fap.index()) - 1);
        Some(below.count_ones() as usize)
    }

    /// Union of two masks.
    pub const fn union(self, other: FapMask) -> FapMask {
        FapMask(self.0 | other.0)
    }

    /// The FAPs present, in increasing order.
    pub fn iter(self) -> impl Iterator<Item = FapId> + Clone {
        let mut bits = self.0;
        std::iter::from_fn(move || {
            if bits == 0 {
                return None;
            }
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            FapId::from_index(i)
        })
    }
}

impl FromIterator<FapId> for FapMask {
    fn from_iter<I: IntoIterator<Item = FapId>>(iter: I) -> Self {
        let mut m = FapMask::EMPTY;
        for id in iter {
            m.insert(id);
        }
        m
    }
}

impl fmt::Display for FapMask {
    /// The 68 entries as `0`/`1` tokens separated by single spaces (a `.fap` mask line).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut buf = [b' '; 2 * NUM_FAPS - 1];
        for i in 0..NUM_FAPS {
            buf[2 * i] = if self.0 & (1u128 << i) != 0 {
                b'1'
            } else {
                b'0'
            };
        }
        // The buffer holds only ASCII.
        f.write_str(std::str::from_utf8(&buf).map_err(|_| fmt::Error)?)
    }
}

impl FromStr for FapMask {
    type Err = String;
    /// Exactly 68 whitespace-separated `0`/`1` tokens.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut m = FapMask::EMPTY;
        let mut n = 0;
        for tok in s.split_ascii_whitespace() {
            if n >= NUM_FAPS {
                return Err(format!("more than {NUM_FAPS} mask entries"));
            }
            match tok {
                "0" => {}
                "1" => m.0 |= 1u128 << n,
                _ => return Err(format!("mask entry {} is `{tok}`, not 0 or 1", n + 1)),
            }
            n += 1;
        }
        if n != NUM_FAPS {
            return Err(format!("{n} mask entries, expected {NUM_FAPS}"));
        }
        Ok(m)
    }
}

/// FAP 1 as transmitted: two visemes and their blend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct VisemeParams {
    /// First viseme.
    pub select1: Viseme,
    /// Second viseme.
    pub select2: Viseme,
    /// 0..=63: weight of `select1` is `blend / 63`, of `select2` the rest.
    pub blend: u8,
    /// `viseme_def` bit.
    pub def: bool,
}

impl VisemeParams {
    /// Largest blend value.
    pub const MAX_BLEND: u8 = 63;

    /// Silence on both selects (the state before any viseme was transmitted).
    pub const NEUTRAL: VisemeParams = VisemeParams {
        select1: match Viseme::new(0) {
            Some(v) => v,
            None => unreachable!(),
        },
        select2: match Viseme::new(0) {
            Some(v) => v,
            None => unreachable!(),
        },
        blend: 0,
        def: false,
    };
}

/// FAP 2 as transmitted: two expressions with their intensities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ExpressionParams {
    /// First expression.
    pub select1: Expression,
    /// 0..=63.
    pub intensity1: u8,
    /// Second expression.
    pub select2: Expression,
    /// 0..=63.
    pub intensity2: u8,
    /// `init_face` bit.
    pub init_face: bool,
    /// `expression_def` bit.
    pub def: bool,
}

impl ExpressionParams {
    /// Largest intensity value.
    pub const MAX_INTENSITY: u8 = 63;

    /// Neutral with zero intensities (the state before any expression was transmitted).
    pub const NEUTRAL: ExpressionParams = ExpressionParams {
        select1: Expression::Neutral,
        intensity1: 0,
        select2: Expression::Neutral,
        intensity2: 0,
        init_face: false,
        def: false,
    };
}

/// One transmitted frame: its number and the FAPs sent in it.
///
/// The mask is kept consistent with the content: bit 1 is set exactly when `viseme` is
/// present, bit 2 when `expression` is, and bits 3..=68 name the low-level values, which are
/// stored densely in increasing FAP order.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FapFrame {
    /// Frame number (time = number / frame rate); counts from 0.
    pub number: u64,
    mask: FapMask,
    values: Vec<f64>,
    viseme: Option<VisemeParams>,
    expression: Option<ExpressionParams>,
}

impl FapFrame {
    /// An empty frame.
    pub fn new(number: u64) -> FapFrame {
        FapFrame {
            number,
            ..FapFrame::default()
        }
    }

    /// A frame from a mask and the low-level values in increasing FAP order; `None` if the
    /// number of values does not match the mask's low-level FAPs, or the mask's high-level
    /// bits disagree with `viseme`/`expression`.
    pub fn from_parts(
        number: u64,
        mask: FapMask,
        values: Vec<f64>,
        viseme: Option<VisemeParams>,
        expression: Option<ExpressionParams>,
    ) -> Option<FapFrame> {
        let ok = mask.low_level_len() == values.len()
            && mask.contains(FapId::VISEME) == viseme.is_some()
            && mask.contains(FapId::EXPRESSION) == expression.is_some();
        ok.then_some(FapFrame {
            number,
            mask,
            values,
            viseme,
            expression,
        })
    }

    /// Which FAPs this frame transmits.
    pub fn mask(&self) -> FapMask {
        self.mask
    }

    /// Value of a low-level FAP if transmitted in this frame (`None` for FAPs 1 and 2; see
    /// [`FapFrame::viseme`] and [`FapFrame::expression`]).
    pub fn value(&self, fap: FapId) -> Option<f64> {
        self.mask.low_level_position(fap).map(|i| self.values[i])
    }

    /// The low-level values, in increasing FAP order (aligned with the mask's FAPs 3..=68).
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The transmitted low-level FAPs with their values.
    pub fn low_level(&self) -> impl Iterator<Item = (FapId, f64)> + '_ {
        self.mask
            .iter()
            .filter(|id| !id.is_high_level())
            .zip(self.values.iter().copied())
    }

    /// FAP 1, if transmitted.
    pub fn viseme(&self) -> Option<VisemeParams> {
        self.viseme
    }

    /// FAP 2, if transmitted.
    pub fn expression(&self) -> Option<ExpressionParams> {
        self.expression
    }

    /// Sets (or adds) a low-level FAP. Panics for FAPs 1 and 2, which carry structured values
    /// (use [`FapFrame::set_viseme`] / [`FapFrame::set_expression`]).
    pub fn set(&mut self, fap: FapId, value: f64) {
        assert!(!fap.is_high_level(), "FAP {fap} is not a low-level FAP");
        if let Some(i) = self.mask.low_level_position(fap) {
            self.values[i] = value;
        } else {
            self.mask.insert(fap);
            let i = self.mask.low_level_position(fap).unwrap_or(0);
            self.values.insert(i, value);
        }
    }

    /// Removes a FAP (any of 1..=68) from the frame.
    pub fn remove(&mut self, fap: FapId) {
        match fap {
            FapId::VISEME => self.viseme = None,
            FapId::EXPRESSION => self.expression = None,
            _ => {
                if let Some(i) = self.mask.low_level_position(fap) {
                    self.values.remove(i);
                }
            }
        }
        self.mask.remove(fap);
    }

    /// Sets or clears FAP 1.
    pub fn set_viseme(&mut self, viseme: Option<VisemeParams>) {
        self.viseme = viseme;
        if viseme.is_some() {
            self.mask.insert(FapId::VISEME);
        } else {
            self.mask.remove(FapId::VISEME);
        }
    }

    /// Sets or clears FAP 2.
    pub fn set_expression(&mut self, expression: Option<ExpressionParams>) {
        self.expression = expression;
        if expression.is_some() {
            self.mask.insert(FapId::EXPRESSION);
        } else {
            self.mask.remove(FapId::EXPRESSION);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// JSON shape of a frame: {"number": 3, "viseme": {...}, "expression": {...},
//                         "faps": {"open_jaw": 120, ...}}
// ---------------------------------------------------------------------------------------------

/// Serialises integral values as integers so JSON reads `120`, not `120.0`.
struct Num(f64);

impl Serialize for Num {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = self.0;
        if v.fract() == 0.0 && v.abs() < 1e15 {
            s.serialize_i64(v as i64)
        } else {
            s.serialize_f64(v)
        }
    }
}

struct NamedValues<'a>(&'a FapFrame);

impl Serialize for NamedValues<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.values.len()))?;
        for (id, v) in self.0.low_level() {
            map.serialize_entry(id.name(), &Num(v))?;
        }
        map.end()
    }
}

impl Serialize for FapFrame {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("number", &self.number)?;
        if let Some(v) = &self.viseme {
            map.serialize_entry("viseme", v)?;
        }
        if let Some(e) = &self.expression {
            map.serialize_entry("expression", e)?;
        }
        map.serialize_entry("faps", &NamedValues(self))?;
        map.end()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameJson {
    number: u64,
    #[serde(default)]
    viseme: Option<VisemeParams>,
    #[serde(default)]
    expression: Option<ExpressionParams>,
    #[serde(default)]
    faps: serde_json::Map<String, serde_json::Value>,
}

impl<'de> Deserialize<'de> for FapFrame {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let j = FrameJson::deserialize(d)?;
        let mut frame = FapFrame::new(j.number);
        check_params(j.viseme, j.expression).map_err(D::Error::custom)?;
        frame.set_viseme(j.viseme);
        frame.set_expression(j.expression);
        for (name, value) in j.faps {
            let id = FapId::from_name(&name)
                .or_else(|| name.parse::<FapId>().ok())
                .filter(|id| !id.is_high_level())
                .ok_or_else(|| D::Error::custom(format!("`{name}` is not a low-level FAP")))?;
            let v = value.as_f64().filter(|v| v.is_finite()).ok_or_else(|| {
                D::Error::custom(format!("FAP `{name}`: {value} is not a number"))
            })?;
            if v.abs() > MAX_ABS_FAP_VALUE {
                return Err(D::Error::custom(format!(
                    "FAP `{name}`: {value} is beyond ±{MAX_ABS_FAP_VALUE:e}"
                )));
            }
            frame.set(id, v);
        }
        Ok(frame)
    }
}

/// Range checks of the FAP 1/2 fields that the field types do not enforce.
fn check_params(v: Option<VisemeParams>, e: Option<ExpressionParams>) -> Result<(), String> {
    if let Some(v) = v {
        if v.blend > VisemeParams::MAX_BLEND {
            return Err(format!("viseme blend {} is above 63", v.blend));
        }
    }
    if let Some(e) = e {
        if e.intensity1 > ExpressionParams::MAX_INTENSITY
            || e.intensity2 > ExpressionParams::MAX_INTENSITY
        {
            return Err("expression intensity above 63".to_string());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id(n: u8) -> FapId {
        FapId::new(n).unwrap()
    }

    #[test]
    fn mask_iterates_and_positions() {
        let m: FapMask = [id(1), id(3), id(19), id(68)].into_iter().collect();
        assert_eq!(
            m.iter().map(|f| f.number()).collect::<Vec<_>>(),
            [1, 3, 19, 68]
        );
        assert_eq!(m.len(), 4);
        assert_eq!(m.low_level_len(), 3);
        assert_eq!(m.low_level_position(id(3)), Some(0));
        assert_eq!(m.low_level_position(id(68)), Some(2));
        assert_eq!(m.low_level_position(id(1)), None);
        assert_eq!(m.low_level_position(id(4)), None);
    }

    #[test]
    fn mask_display_parse_round_trip() {
        let m: FapMask = [id(2), id(3), id(68)].into_iter().collect();
        let s = m.to_string();
        assert_eq!(s.len(), 135);
        assert!(s.starts_with("0 1 1 0"));
        assert!(s.ends_with(" 1"));
        assert_eq!(s.parse::<FapMask>().unwrap(), m);
        assert!("0 1".parse::<FapMask>().is_err());
        assert!(format!("{s} 0").parse::<FapMask>().is_err());
        assert!(s.replace('1', "2").parse::<FapMask>().is_err());
    }

    #[test]
    fn frame_set_keeps_values_in_fap_order() {
        let mut f = FapFrame::new(4);
        f.set(id(19), 1.5);
        f.set(id(3), 100.0);
        f.set(id(19), 2.0);
        assert_eq!(f.values(), &[100.0, 2.0]);
        assert_eq!(f.value(id(19)), Some(2.0));
        assert_eq!(f.value(id(4)), None);
        f.remove(id(3));
        assert_eq!(f.values(), &[2.0]);
        assert!(!f.mask().contains(id(3)));
        f.set_viseme(Some(VisemeParams::NEUTRAL));
        assert!(f.mask().contains(FapId::VISEME));
        assert!(FapFrame::from_parts(0, f.mask(), vec![], None, None).is_none());
    }

    #[test]
    fn json_uses_names_and_integers_and_round_trips() {
        let mut f = FapFrame::new(2);
        f.set(FapId::OPEN_JAW, 120.0);
        f.set(id(48), -0.5);
        f.set_expression(Some(ExpressionParams {
            select1: Expression::Joy,
            intensity1: 40,
            ..ExpressionParams::NEUTRAL
        }));
        let s = FapStream {
            frames: vec![f],
            ..FapStream::new("demo", 25.0)
        };
        let j = serde_json::to_string(&s).unwrap();
        assert!(
            j.contains(r#""faps":{"open_jaw":120,"head_pitch":-0.5}"#),
            "{j}"
        );
        assert!(j.contains(r#""select1":"joy""#), "{j}");
        let back: FapStream = serde_json::from_str(&j).unwrap();
        assert_eq!(back, s);
        let bad = j.replace("open_jaw", "open_jawx");
        assert!(serde_json::from_str::<FapStream>(&bad).is_err());
    }

    #[test]
    fn problems_name_bad_content() {
        let mut s = FapStream::new("x", 0.0);
        let mut f = FapFrame::new(1);
        f.set(FapId::OPEN_JAW, -1.0);
        s.frames = vec![f.clone(), f];
        let p = s.problems();
        assert_eq!(p.len(), 4, "{p:?}");
    }
}
