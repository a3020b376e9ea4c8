//! The facts of the MPEG-4 FBA standard as typed, static tables.
//!
//! The machine-readable sources are the CSV files in `specs/` at the crate root; the tables
//! here are their compiled form (see `fap_table.rs` and `feature_point_table.rs`), and the tests
//! at the bottom of this file pin every row against the CSV so a typo cannot slip in.
//!
//! Coordinates follow the MPEG-4 face frame: right-handed, **+x towards the face's own left**,
//! +y up, +z out of the face towards the viewer (the gaze direction).

mod fap_table;
mod feature_point_ids;
mod feature_point_table;

use std::fmt;
use std::str::FromStr;

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Number of Facial Animation Parameters (2 high-level + 66 low-level).
pub const NUM_FAPS: usize = 68;

/// Number of facial feature points in groups 2..=11.
pub const NUM_FEATURE_POINTS: usize = 84;

/// The angle unit AU in radians (fixed by the standard, not measured on a face).
pub const AU_RADIANS: f64 = 1e-5;

/// The divisor that turns a neutral-face distance into its FAP unit.
pub const FAPU_DIVISOR: f64 = 1024.0;

// ---------------------------------------------------------------------------------------------
// FAP identifiers and their table rows
// ---------------------------------------------------------------------------------------------

/// A Facial Animation Parameter number, 1..=68 (1 = viseme, 2 = expression, 3..=68 low-level).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct FapId(u8);

impl FapId {
    /// FAP 1, the high-level viseme.
    pub const VISEME: FapId = FapId(1);
    /// FAP 2, the high-level expression.
    pub const EXPRESSION: FapId = FapId(2);
    /// FAP 3, `open_jaw` (handy in examples and tests).
    pub const OPEN_JAW: FapId = FapId(3);

    /// The FAP with this 1-based number, if it exists.
    pub const fn new(number: u8) -> Option<FapId> {
        if number >= 1 && number as usize <= NUM_FAPS {
            Some(FapId(number))
        } else {
            None
        }
    }

    /// The FAP at this 0-based position (mask position in a `.fap` file).
    pub const fn from_index(index: usize) -> Option<FapId> {
        if index < NUM_FAPS {
            Some(FapId(index as u8 + 1))
        } else {
            None
        }
    }

    /// The FAP whose standard table name is `name` (e.g. `open_jaw`).
    pub fn from_name(name: &str) -> Option<FapId> {
        FAP_TABLE_REF
            .iter()
            .find(|f| f.name == name)
            .map(|info| FapId(info.number))
    }

    /// The FAP whose BIFS `FAP` node field name is `name`. Six differ from the table names,
    /// and `stretch_l_cornerlip` is FAP 6 in the table but FAP 53 in BIFS, so the two name
    /// spaces are looked up separately.
    pub fn from_bifs_field_name(name: &str) -> Option<FapId> {
        FapId::low_level().find(|&id| bifs_field_name(id) == name)
    }

    /// All 68 FAPs in order.
    pub fn all() -> impl DoubleEndedIterator<Item = FapId> + ExactSizeIterator + Clone {
        (1..=NUM_FAPS as u8).map(FapId)
    }

    /// The 66 low-level FAPs (3..=68) in order.
    pub fn low_level() -> impl DoubleEndedIterator<Item = FapId> + ExactSizeIterator + Clone {
        (3..=NUM_FAPS as u8).map(FapId)
    }

    /// 1-based FAP number.
    pub const fn number(self) -> u8 {
        self.0
    }

    /// 0-based position (mask bit, array index).
    pub const fn index(self) -> usize {
        self.0 as usize - 1
    }

    /// True for FAP 1 (viseme) and FAP 2 (expression).
    pub const fn is_high_level(self) -> bool {
        self.0 <= 2
    }

    /// The standard's table row for this FAP.
    pub fn info(self) -> &'static FapInfo {
        &FAP_TABLE_REF[self.index()]
    }

    /// The standard name, e.g. `open_jaw`.
    pub fn name(self) -> &'static str {
        self.info().name
    }
}

impl fmt::Display for FapId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl TryFrom<u8> for FapId {
    type Error = String;
    fn try_from(n: u8) -> Result<Self, Self::Error> {
        FapId::new(n).ok_or_else(|| format!("FAP number {n} is outside 1..=68"))
    }
}

impl From<FapId> for u8 {
    fn from(id: FapId) -> u8 {
        id.0
    }
}

impl FromStr for FapId {
    type Err = String;
    /// Accepts a number (`3`) or a name (`open_jaw`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if let Ok(n) = s.parse::<u32>() {
            return u8::try_from(n)
                .ok()
                .and_then(FapId::new)
                .ok_or_else(|| format!("FAP number {n} is outside 1..=68"));
        }
        FapId::from_name(s).ok_or_else(|| format!("`{s}` is not a FAP number or name"))
    }
}

/// What a FAP group (1..=10, [`FapInfo::group`]) moves, as the standard's group table says
/// (`visemes and expressions`, `jaw, chin, inner lip, lip corners`, …); `None` outside 1..=10.
pub fn fap_group_content(group: u8) -> Option<&'static str> {
    Some(match group {
        1 => "visemes and expressions",
        2 => "jaw, chin, inner lip, lip corners",
        3 => "eyelids, eyeballs, pupils",
        4 => "eyebrows",
        5 => "cheeks",
        6 => "tongue",
        7 => "head rotation",
        8 => "outer lip",
        9 => "nose",
        10 => "ears",
        _ => return None,
    })
}

/// The BIFS `FAP` node field name of a low-level FAP (differs from the table name for six FAPs).
pub fn bifs_field_name(id: FapId) -> &'static str {
    match id.number() {
        6 => "stretch_l_corner",
        7 => "stretch_r_corner",
        10 => "lower_b_lip_lm",
        11 => "lower_b_lip_rm",
        53 => "stretch_l_cornerlip",
        54 => "stretch_r_cornerlip",
        _ => id.name(),
    }
}

static FAP_TABLE_REF: &[FapInfo; NUM_FAPS] = &fap_table::FAP_TABLE;

/// One row of the standard's FAP table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FapInfo {
    /// 1-based FAP number.
    pub number: u8,
    /// Standard name, e.g. `open_jaw`.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The unit the FAP value is measured in; `None` for the high-level FAPs 1 and 2.
    pub fapu: Option<FapuKind>,
    /// Whether negative values are allowed; `None` for FAPs 1 and 2.
    pub directionality: Option<Directionality>,
    /// What a positive value does; `None` for FAPs 1 and 2.
    pub positive_motion: Option<PositiveMotion>,
    /// FAP group (1 for FAPs 1–2; otherwise equal to the feature-point group moved).
    pub group: u8,
    /// Feature points the FAP moves (empty for FAPs 1 and 2; two for `tongue_roll`).
    pub feature_points: &'static [FeaturePointId],
    /// Quantisation step of the predictive bitstream coder.
    pub quant_step: u16,
}

impl FapInfo {
    /// The FAP's id.
    pub fn id(&self) -> FapId {
        FapId(self.number)
    }

    /// True when the FAP is an angle (unit AU).
    pub fn is_rotation(&self) -> bool {
        self.fapu == Some(FapuKind::Au)
    }

    /// Unit vector along which a positive value moves the feature point, for translation FAPs.
    ///
    /// `None` for FAPs 1–2, for pupil dilation (a radial change, no single direction) and for
    /// the angle FAPs (see [`FapInfo::rotation_axis`]). For `tongue_roll` (an angle that lifts
    /// both tongue borders) it is also `None`.
    pub fn direction(&self) -> Option<Vec3> {
        if self.is_rotation() {
            return None;
        }
        self.positive_motion.and_then(PositiveMotion::translation)
    }

    /// Axis of the right-handed rotation produced by a positive value, for the eyeball and head
    /// angle FAPs (23–26, 48–50). Pitch turns about +x (looks down), yaw about +y (turns to the
    /// face's left), roll about +z (top of the head tips to the face's right).
    pub fn rotation_axis(&self) -> Option<Vec3> {
        if !self.is_rotation() {
            return None;
        }
        match self.number {
            25 | 26 | 48 => Some(Vec3::X),
            23 | 24 | 49 => Some(Vec3::Y),
            50 => Some(Vec3::Z),
            _ => None,
        }
    }

    /// Whether `value` is allowed by the directionality (unidirectional FAPs take only `>= 0`).
    pub fn accepts(&self, value: f64) -> bool {
        value.is_finite()
            && !(self.directionality == Some(Directionality::Unidirectional) && value < 0.0)
    }
}

/// The six FAP units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum FapuKind {
    /// Iris diameter IRISD0 / 1024.
    #[serde(rename = "IRISD")]
    Irisd,
    /// Eye separation ES0 / 1024.
    #[serde(rename = "ES")]
    Es,
    /// Eye–nose separation ENS0 / 1024.
    #[serde(rename = "ENS")]
    Ens,
    /// Mouth–nose separation MNS0 / 1024.
    #[serde(rename = "MNS")]
    Mns,
    /// Mouth width MW0 / 1024.
    #[serde(rename = "MW")]
    Mw,
    /// Angle unit, 1e-5 rad.
    #[serde(rename = "AU")]
    Au,
}

impl FapuKind {
    /// All six, in the order IRISD, ES, ENS, MNS, MW, AU.
    pub const ALL: [FapuKind; 6] = [
        FapuKind::Irisd,
        FapuKind::Es,
        FapuKind::Ens,
        FapuKind::Mns,
        FapuKind::Mw,
        FapuKind::Au,
    ];

    /// The standard abbreviation (`IRISD`, `ES`, `ENS`, `MNS`, `MW`, `AU`).
    pub const fn abbreviation(self) -> &'static str {
        match self {
            FapuKind::Irisd => "IRISD",
            FapuKind::Es => "ES",
            FapuKind::Ens => "ENS",
            FapuKind::Mns => "MNS",
            FapuKind::Mw => "MW",
            FapuKind::Au => "AU",
        }
    }
}

impl fmt::Display for FapuKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.abbreviation())
    }
}

impl FromStr for FapuKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let upper = s.trim().to_ascii_uppercase();
        let upper = upper.strip_suffix('0').unwrap_or(&upper);
        FapuKind::ALL
            .into_iter()
            .find(|k| k.abbreviation() == upper)
            .ok_or_else(|| format!("`{s}` is not a FAPU (IRISD, ES, ENS, MNS, MW, AU)"))
    }
}

/// Whether a FAP takes negative values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Directionality {
    /// Only values `>= 0` (open_jaw, thrust_jaw, lift cheeks, tongue_roll).
    Unidirectional,
    /// Any sign.
    Bidirectional,
}

/// The standard's word for what a positive FAP value does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PositiveMotion {
    /// −y.
    Down,
    /// +y.
    Up,
    /// Towards the face's own left, +x.
    Left,
    /// Towards the face's own right, −x.
    Right,
    /// Out of the face, +z.
    Forward,
    /// Pupil grows (radial).
    Growing,
    /// Tongue rolls so both borders rise.
    ConcaveUpward,
}

impl PositiveMotion {
    /// The unit vector for a translation word, `None` for the radial and rolling words.
    pub const fn translation(self) -> Option<Vec3> {
        match self {
            PositiveMotion::Down => Some(Vec3::NEG_Y),
            PositiveMotion::Up => Some(Vec3::Y),
            PositiveMotion::Left => Some(Vec3::X),
            PositiveMotion::Right => Some(Vec3::NEG_X),
            PositiveMotion::Forward => Some(Vec3::Z),
            PositiveMotion::Growing | PositiveMotion::ConcaveUpward => None,
        }
    }

    /// The word as written in `specs/fap-table.csv`.
    pub const fn word(self) -> &'static str {
        match self {
            PositiveMotion::Down => "down",
            PositiveMotion::Up => "up",
            PositiveMotion::Left => "left",
            PositiveMotion::Right => "right",
            PositiveMotion::Forward => "forward",
            PositiveMotion::Growing => "growing",
            PositiveMotion::ConcaveUpward => "concave upward",
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Feature points
// ---------------------------------------------------------------------------------------------

/// A facial feature point label such as `2.1` (group 2, index 1); groups 2..=11.
///
/// Only the 84 labels of the standard can be constructed through [`FeaturePointId::new`] and
/// [`FromStr`]; the fields stay private so an id always names a real point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FeaturePointId {
    group: u8,
    index: u8,
}

/// Number of points in each group 2..=11.
const GROUP_SIZES: [u8; 10] = [14, 14, 6, 4, 4, 1, 10, 15, 10, 6];

impl FeaturePointId {
    /// Constant constructor used by the static tables; panics (at compile time in const
    /// context) on a label the standard does not define.
    pub(crate) const fn from_parts(group: u8, index: u8) -> FeaturePointId {
        match FeaturePointId::new(group, index) {
            Some(id) => id,
            None => panic!("not a feature point label"),
        }
    }

    /// The feature point `group.index`, if the standard defines it.
    pub const fn new(group: u8, index: u8) -> Option<FeaturePointId> {
        if group < 2 || group > 11 || index == 0 || index > GROUP_SIZES[group as usize - 2] {
            None
        } else {
            Some(FeaturePointId { group, index })
        }
    }

    /// Group number (2..=11).
    pub const fn group(self) -> u8 {
        self.group
    }

    /// Index within the group (1-based).
    pub const fn index(self) -> u8 {
        self.index
    }

    /// Position in the standard's label order (2.1, 2.2, …, 11.6), 0-based; this is the order
    /// of the FDP node's `featurePointsCoord`.
    pub fn ordinal(self) -> usize {
        let before: usize = GROUP_SIZES[..(self.group as usize - 2)]
            .iter()
            .map(|&n| n as usize)
            .sum();
        before + self.index as usize - 1
    }

    /// The point at this position in the standard's label order.
    pub fn from_ordinal(ordinal: usize) -> Option<FeaturePointId> {
        FEATURE_POINT_TABLE_REF.get(ordinal).map(|row| row.id)
    }

    /// All 84 points in the standard's label order.
    pub fn all() -> impl DoubleEndedIterator<Item = FeaturePointId> + ExactSizeIterator + Clone {
        FEATURE_POINT_TABLE_REF.iter().map(|row| row.id)
    }

    /// The standard's table row for this point.
    pub fn info(self) -> &'static FeaturePointInfo {
        &FEATURE_POINT_TABLE_REF[self.ordinal()]
    }
}

impl fmt::Display for FeaturePointId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}", self.group, self.index)
    }
}

impl FromStr for FeaturePointId {
    type Err = String;
    /// Parses `group.index`, e.g. `3.5`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        let (g, i) = t.split_once('.').ok_or_else(|| {
            format!("`{s}` is not a feature point label (expected group.index such as 2.1)")
        })?;
        let g: u8 = g
            .parse()
            .map_err(|_| format!("`{s}`: feature point group must be a number 2..=11"))?;
        let i: u8 = i
            .parse()
            .map_err(|_| format!("`{s}`: feature point index must be a positive number"))?;
        FeaturePointId::new(g, i).ok_or_else(|| {
            format!("`{s}` is not one of the 84 MPEG-4 feature points (2.1 .. 11.6)")
        })
    }
}

impl Serialize for FeaturePointId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for FeaturePointId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Which side of the face a feature point is on (the face's own left/right).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Side {
    /// The face's own left (+x).
    Left,
    /// The face's own right (−x).
    Right,
    /// On the midline.
    Middle,
}

static FEATURE_POINT_TABLE_REF: &[FeaturePointInfo; NUM_FEATURE_POINTS] =
    &feature_point_table::FEATURE_POINT_TABLE;

/// One row of the standard's feature-point table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FeaturePointInfo {
    /// The label.
    pub id: FeaturePointId,
    /// Where on the face it lies.
    pub description: &'static str,
    /// Side of the face.
    pub side: Side,
    /// Region name (e.g. `inner lip`).
    pub region: &'static str,
    /// Which FAPU it is an end of, if any (free text from the table).
    pub fapu_use: &'static str,
    /// FAP numbers that move it.
    pub moved_by: &'static [u8],
    /// Caveats recorded with the row.
    pub notes: &'static str,
}

// ---------------------------------------------------------------------------------------------
// Visemes and expressions
// ---------------------------------------------------------------------------------------------

/// The 15 visemes of FAP 1 (0 = silence/none, 1..=14 mouth shapes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub struct Viseme(u8);

/// SAMPA phonemes of each viseme, by number; from `specs/visemes.csv`.
const VISEME_PHONEMES: [&[&str]; 15] = [
    &[],
    &["p", "b", "m"],
    &["f", "v"],
    &["T", "D"],
    &["t", "d"],
    &["k", "g"],
    &["tS", "dZ", "S"],
    &["s", "z"],
    &["n", "l"],
    &["r"],
    &["A:"],
    &["e"],
    &["I"],
    &["Q"],
    &["U"],
];

const VISEME_LABELS: [&str; 15] = [
    "sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E", "ih", "oh", "ou",
];

impl Viseme {
    /// Number of visemes including 0 (none).
    pub const COUNT: usize = 15;

    /// The viseme with this number (0..=14).
    pub const fn new(number: u8) -> Option<Viseme> {
        if (number as usize) < Self::COUNT {
            Some(Viseme(number))
        } else {
            None
        }
    }

    /// Its number, 0..=14.
    pub const fn number(self) -> u8 {
        self.0
    }

    /// The 14 mouth shapes (1..=14), those that a FAT has tables for.
    pub fn shapes() -> impl DoubleEndedIterator<Item = Viseme> + ExactSizeIterator + Clone {
        (1..Self::COUNT as u8).map(Viseme)
    }

    /// SAMPA phonemes it represents (empty for 0).
    pub fn phonemes(self) -> &'static [&'static str] {
        VISEME_PHONEMES[self.0 as usize]
    }

    /// Common short label (visage / Oculus naming), e.g. `PP`.
    pub fn label(self) -> &'static str {
        VISEME_LABELS[self.0 as usize]
    }

    /// The viseme whose label or number is `s` (`PP`, `viseme_1`, `1`).
    pub fn from_label(s: &str) -> Option<Viseme> {
        let t = s.trim();
        let t = t.strip_prefix("viseme_").unwrap_or(t);
        if let Ok(n) = t.parse::<u8>() {
            return Viseme::new(n);
        }
        VISEME_LABELS
            .iter()
            .position(|l| l.eq_ignore_ascii_case(t))
            .map(|i| Viseme(i as u8))
    }
}

impl TryFrom<u8> for Viseme {
    type Error = String;
    fn try_from(n: u8) -> Result<Self, Self::Error> {
        Viseme::new(n).ok_or_else(|| format!("viseme {n} is outside 0..=14"))
    }
}

impl From<Viseme> for u8 {
    fn from(v: Viseme) -> u8 {
        v.0
    }
}

/// The expressions of FAP 2 (0 = neutral, 1..=6 the basic expressions).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Expression {
    /// No expression (0).
    Neutral = 0,
    /// 1.
    Joy = 1,
    /// 2.
    Sadness = 2,
    /// 3.
    Anger = 3,
    /// 4.
    Fear = 4,
    /// 5.
    Disgust = 5,
    /// 6.
    Surprise = 6,
}

impl Expression {
    /// All seven, neutral first.
    pub const ALL: [Expression; 7] = [
        Expression::Neutral,
        Expression::Joy,
        Expression::Sadness,
        Expression::Anger,
        Expression::Fear,
        Expression::Disgust,
        Expression::Surprise,
    ];

    /// The expression with this number (0..=6).
    pub fn new(number: u8) -> Option<Expression> {
        Self::ALL.get(number as usize).copied()
    }

    /// Its number, 0..=6.
    pub const fn number(self) -> u8 {
        self as u8
    }

    /// The six basic expressions (1..=6), those that a FAT has tables for.
    pub fn basic() -> impl DoubleEndedIterator<Item = Expression> + ExactSizeIterator + Clone {
        Self::ALL[1..].iter().copied()
    }

    /// Lower-case name, e.g. `joy`.
    pub const fn name(self) -> &'static str {
        match self {
            Expression::Neutral => "neutral",
            Expression::Joy => "joy",
            Expression::Sadness => "sadness",
            Expression::Anger => "anger",
            Expression::Fear => "fear",
            Expression::Disgust => "disgust",
            Expression::Surprise => "surprise",
        }
    }

    /// The expression named `s` (case-insensitive) or numbered `s`.
    pub fn from_name(s: &str) -> Option<Expression> {
        let t = s.trim();
        if let Ok(n) = t.parse::<u8>() {
            return Expression::new(n);
        }
        Self::ALL
            .into_iter()
            .find(|e| e.name().eq_ignore_ascii_case(t))
    }
}

impl fmt::Display for Expression {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests;
