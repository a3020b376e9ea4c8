//! How far each ARKit shape moves each MPEG-4 FAP, in FAP units: the recipe that turns any
//! face with a FAT into ARKit-named blend shapes ([`super::arkit_export`]).
//!
//! The table `specs/arkit-fap-amplitudes.csv` has the columns `shape,fap,value,unit,source`:
//! ARKit shape `shape` at weight 1 shows FAP `fap` at `value` (signed, in `unit`). Which FAPs
//! a shape realises, and with which sign, is [`super::fap_map`]'s ARKit preset; the values are
//! **measured** on a real rig by [`measure_amplitudes`] — the calibrated sides of
//! [`super::fat_build::face_from_rig`] (`CalibratedSide::value`, the FAP value the side's
//! shapes show at weight 1):
//!
//! - a side played by one shape gives that shape its value;
//! - a side played by a sum of shapes (`mouthUpperUpLeft+mouthUpperUpRight` lowering the
//!   mid upper lip) splits its value between them in proportion to each shape's own motion of
//!   the side's feature point along the FAP's direction (evenly when that is not measurable);
//! - a rig's half shapes (`browInnerUp_L`) count for the ARKit shape they are half of.
//!
//! The bundled table was measured on the ICT-FaceKit rig with feature points derived from its
//! iBUG-68 landmarks (`examples/make_arkit_amplitudes.rs` writes it; a test regenerates and
//! compares it). Because the values are in FAP units, they mean the same on any face.

use std::path::Path;

use serde::Serialize;

use super::arkit_names::{arkit_index_of_rig_shape, ARKIT_SHAPES};
use super::fat_build::RigFatReport;
use super::Rig;
use crate::error::{Error, ParseError, Result};
use crate::face::FaceModel;
use crate::fdp::Fapu;
use crate::spec::{FapId, FeaturePointId};

/// The bundled table.
pub const ARKIT_AMPLITUDES_CSV: &str = include_str!("../../specs/arkit-fap-amplitudes.csv");

/// Most rows an amplitude table may have.
const MAX_ROWS: usize = 4096;

/// One row: ARKit shape `shape` at weight 1 shows `fap` at `value`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Amplitude {
    /// ARKit name as Apple spells it (`jawOpen`).
    pub shape: String,
    /// The FAP.
    pub fap: FapId,
    /// FAP value (signed, FAP units).
    pub value: f64,
    /// The FAP unit's abbreviation (`MNS`).
    pub unit: String,
    /// Where the value comes from.
    pub source: String,
}

/// The bundled ARKit amplitudes (`specs/arkit-fap-amplitudes.csv`).
pub fn arkit_amplitudes() -> Vec<Amplitude> {
    parse_amplitudes(
        ARKIT_AMPLITUDES_CSV,
        Path::new("specs/arkit-fap-amplitudes.csv"),
    )
    .expect("the bundled amplitude table parses")
}

/// Measures the amplitudes on `rig`, from its `face` (built by `face_from_rig`, so with its
/// feature points) and the calibration `report` (module docs). Rows come in
/// [`ARKIT_SHAPES`] order, then FAP number.
pub fn measure_amplitudes(
    rig: &Rig,
    face: &FaceModel,
    report: &RigFatReport,
    source: &str,
) -> Result<Vec<Amplitude>> {
    let fapu = Fapu::from_feature_points(&face.feature_points)?;
    let mut rows: Vec<(usize, Amplitude)> = Vec::new();
    for c in &report.calibrated {
        let Some(fap) = FapId::from_name(&c.fap) else {
            continue;
        };
        let terms: Vec<(String, f64)> = c
            .shapes
            .iter()
            .map(|s| match s.split_once('*') {
                Some((n, w)) => (n.to_string(), w.parse().unwrap_or(1.0)),
                None => (s.clone(), 1.0),
            })
            .collect();
        let shares = split_shares(rig, face, &fapu, fap, &c.feature_point, &terms);
        let whole = terms.len() == 1;
        for ((name, _), share) in terms.iter().zip(&shares) {
            let Some(a) = arkit_index_of_rig_shape(name) else {
                continue;
            };
            let how = if whole {
                format!(
                    "{source}: {} ({}) of {name} at FP {}",
                    c.fap, c.sign, c.feature_point
                )
            } else {
                format!(
                    "{source}: {} ({}) of {} at FP {}; share {share:.3} by own motion",
                    c.fap,
                    c.sign,
                    c.shapes.join("+"),
                    c.feature_point
                )
            };
            let value = c.value * share;
            match rows.iter_mut().find(|(i, r)| *i == a && r.fap == fap) {
                Some((_, r)) => {
                    r.value += value;
                    r.source = format!("{}; {how}", r.source);
                }
                None => rows.push((
                    a,
                    Amplitude {
                        shape: ARKIT_SHAPES[a].to_string(),
                        fap,
                        value,
                        unit: c.unit.clone(),
                        source: how,
                    },
                )),
            }
        }
    }
    rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.fap.cmp(&b.1.fap)));
    Ok(rows.into_iter().map(|(_, r)| r).collect())
}

/// Each term's share of a side's value: its own motion of the feature point along the FAP's
/// direction, over the sum; even shares when that is not measurable.
fn split_shares(
    rig: &Rig,
    face: &FaceModel,
    fapu: &Fapu,
    fap: FapId,
    fp: &str,
    terms: &[(String, f64)],
) -> Vec<f64> {
    let even = vec![1.0 / terms.len().max(1) as f64; terms.len()];
    if terms.len() < 2 {
        return even;
    }
    let (Some(dir), Some(unit)) = (fap.info().direction(), fapu.unit_of(fap)) else {
        return even;
    };
    let Some((m, v)) = fp
        .parse::<FeaturePointId>()
        .ok()
        .and_then(|id| face.fp_vertex(id))
    else {
        return even;
    };
    let own: Option<Vec<f64>> = terms
        .iter()
        .map(|(name, w)| {
            rig.shape(name)
                .map(|s| s.offset(m, v).as_dvec3().dot(dir.as_dvec3()) * w / unit)
        })
        .collect();
    let Some(own) = own else { return even };
    let total: f64 = own.iter().sum();
    if total.abs() < 1e-9 || own.iter().any(|o| o * total < 0.0) {
        return even;
    }
    own.iter().map(|o| o / total).collect()
}

/// The CSV text of an amplitude table (header, one row each, values to 0.1 FAPU).
pub fn amplitudes_csv(rows: &[Amplitude]) -> String {
    let mut out = String::from("shape,fap,value,unit,source\n");
    for r in rows {
        out.push_str(&format!(
            "{},{},{:.1},{},\"{}\"\n",
            r.shape,
            r.fap.name(),
            r.value,
            r.unit,
            r.source.replace('"', "'")
        ));
    }
    out
}

/// Parses an amplitude table; `file` names it in errors (`file:line:column: expected ...`).
pub fn parse_amplitudes(text: &str, file: &Path) -> Result<Vec<Amplitude>> {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(text.as_bytes());
    let err_at = |offset: usize, expected: String| -> Error {
        ParseError::at_offset(file, text, offset, expected).into()
    };
    let headers = reader
        .headers()
        .map_err(|e| err_at(0, format!("a CSV header ({e})")))?
        .clone();
    let got: Vec<String> = headers
        .iter()
        .map(|h| h.trim().to_ascii_lowercase())
        .collect();
    if got != ["shape", "fap", "value", "unit", "source"] {
        return Err(err_at(0, "the header `shape,fap,value,unit,source`".into()));
    }
    let mut rows = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let offset = reader.position().byte() as usize;
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => {
                let at = e.position().map_or(offset, |p| p.byte() as usize);
                return Err(err_at(at, format!("a CSV record ({e})")));
            }
        }
        if record.iter().all(|f| f.trim().is_empty()) {
            continue;
        }
        if rows.len() >= MAX_ROWS {
            return Err(err_at(offset, format!("at most {MAX_ROWS} rows")));
        }
        if record.len() != 5 {
            return Err(err_at(
                offset,
                "5 fields: shape,fap,value,unit,source".into(),
            ));
        }
        let shape = record[0].trim();
        let Some(a) = ARKIT_SHAPES.iter().find(|a| **a == shape) else {
            return Err(err_at(
                offset,
                "an ARKit shape name as Apple spells it (jawOpen, eyeBlinkLeft, ...)".into(),
            ));
        };
        let fap = record[1]
            .trim()
            .parse::<FapId>()
            .ok()
            .filter(|f| !f.is_high_level())
            .ok_or_else(|| {
                err_at(
                    offset + record[0].len() + 1,
                    "a low-level FAP name or number".into(),
                )
            })?;
        let value = record[2]
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                err_at(
                    offset + record[0].len() + record[1].len() + 2,
                    "a finite FAP value".into(),
                )
            })?;
        rows.push(Amplitude {
            shape: (*a).to_string(),
            fap,
            value,
            unit: record[3].trim().to_string(),
            source: record[4].to_string(),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_table_parses_and_round_trips() {
        let rows = arkit_amplitudes();
        assert!(rows
            .iter()
            .any(|r| r.shape == "jawOpen" && r.fap.name() == "open_jaw"));
        let again = parse_amplitudes(&amplitudes_csv(&rows), Path::new("x.csv")).unwrap();
        assert_eq!(again.len(), rows.len());
    }

    #[test]
    fn bad_tables_are_located() {
        let e = |t: &str| {
            parse_amplitudes(t, Path::new("a.csv"))
                .unwrap_err()
                .to_string()
        };
        assert!(e("").contains("a.csv:1:1"));
        assert!(e("shape,fap\n").contains("expected the header"));
        let h = "shape,fap,value,unit,source\n";
        assert!(e(&format!("{h}JawOpen,open_jaw,1,MNS,x\n"))
            .contains("a.csv:2:1: expected an ARKit shape"));
        assert!(e(&format!("{h}jawOpen,nope,1,MNS,x\n"))
            .contains("a.csv:2:9: expected a low-level FAP"));
        assert!(e(&format!("{h}jawOpen,open_jaw,NaN,MNS,x\n"))
            .contains("a.csv:2:18: expected a finite"));
        assert!(e(&format!("{h}jawOpen,open_jaw\n")).contains("expected 5 fields"));
    }
}
