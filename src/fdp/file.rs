//! One entry point for every feature-point file format.

use std::path::Path;

use serde::Serialize;

use super::csv::FeaturePointTable;
use super::xface::XfaceFdp;
use crate::error::{Error, Result};
use crate::fdp::{Fapu, FapuDistances, FapuMeasurement, FeaturePointSet};

/// The feature-point file formats fbakit reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FeaturePointFormat {
    /// fbakit's own XML (`.xml`, root `<featurePoints>`).
    FbakitXml,
    /// Xface `.fdp` XML (root `<xfdp>`).
    XfaceFdp,
    /// CSV table `fp,vertices,combine,description` (`.csv`).
    Csv,
}

/// What only one format carries.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "format", rename_all = "kebab-case")]
pub enum FormatExtras {
    /// fbakit XML: the declared length unit.
    FbakitXml {
        /// `units` attribute.
        units: Option<String>,
    },
    /// Xface: head transform, entities, every `<fdp>` element.
    XfaceFdp(XfaceFdp),
    /// CSV: all rows, including `absent` ones and descriptions.
    Csv(FeaturePointTable),
}

/// A feature-point file of any format.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FeaturePointFile {
    /// The format it was read as.
    pub format: FeaturePointFormat,
    /// The points.
    pub points: FeaturePointSet,
    /// FAPU distances written in the file (they take precedence over measuring the points).
    pub fapu: Option<FapuDistances>,
    /// Format-specific content.
    pub extras: FormatExtras,
}

/// Where a file's FAP units came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum FapuSource {
    /// Distances written in the file (Xface `<fapu>`, fbakit `<fapu>`).
    File,
    /// Measured on the feature points' positions.
    FeaturePoints,
}

impl FeaturePointFile {
    /// The file's FAP units: the explicit distances if it has them, else measured on the
    /// points (which must have positions; see [`FeaturePointSet::resolve_positions`]).
    pub fn fapu(&self) -> Result<(FapuSource, FapuMeasurement)> {
        match self.fapu {
            Some(d) => {
                let fapu = Fapu::from_distances(d)?;
                Ok((
                    FapuSource::File,
                    FapuMeasurement {
                        fapu,
                        notes: Vec::new(),
                    },
                ))
            }
            None => Ok((FapuSource::FeaturePoints, Fapu::measure(&self.points)?)),
        }
    }
}

/// Picks the format from the extension (`.xml`, `.fdp`, `.csv`), else from the content.
pub fn detect_format(path: &Path, text: &str) -> Option<FeaturePointFormat> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("csv") => return Some(FeaturePointFormat::Csv),
        Some("fdp") if text.trim_start().starts_with('<') => {
            return Some(FeaturePointFormat::XfaceFdp)
        }
        _ => {}
    }
    // Look at the first few KiB only: enough to pass a declaration and comments.
    let mut end = text.len().min(4096);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let head = &text[..end];
    if head.contains("<featurePoints") {
        Some(FeaturePointFormat::FbakitXml)
    } else if head.contains("<xfdp") {
        Some(FeaturePointFormat::XfaceFdp)
    } else if ext.as_deref() == Some("xml") {
        Some(FeaturePointFormat::FbakitXml)
    } else if head.trim_start().to_ascii_lowercase().starts_with("fp,")
        || head.lines().next().is_some_and(|l| l.contains("vertices"))
    {
        Some(FeaturePointFormat::Csv)
    } else {
        None
    }
}

/// Reads a feature-point file, picking the format with [`detect_format`].
///
/// ```
/// let file = fbakit::fdp::read_feature_points("samples/feature-points-example.xml")?;
/// assert!(file.points.iter().count() > 0);
/// # Ok::<(), fbakit::error::Error>(())
/// ```
pub fn read_feature_points(path: impl AsRef<Path>) -> Result<FeaturePointFile> {
    let path = path.as_ref();
    let text = crate::io::read_text(path)?;
    parse_feature_points(&text, path)
}

/// Reads feature points of any supported format from `reader` (UTF-8, bounded by
/// [`crate::io::DEFAULT_MAX_INPUT_BYTES`]); `source` names it and its extension picks the
/// format.
pub fn read_feature_points_from<R: std::io::BufRead>(
    reader: R,
    source: &Path,
) -> Result<FeaturePointFile> {
    let text = crate::io::read_text_from(reader, source, crate::io::DEFAULT_MAX_INPUT_BYTES)?;
    parse_feature_points(&text, source)
}

/// Parses feature-point text of any supported format; `path` names it and picks the format.
pub fn parse_feature_points(text: &str, path: &Path) -> Result<FeaturePointFile> {
    let format = detect_format(path, text).ok_or_else(|| {
        Error::Unsupported(format!(
            "{}: not a feature-point file (expected fbakit .xml with <featurePoints>, Xface .fdp with <xfdp>, or .csv with fp,vertices columns)",
            path.display()
        ))
    })?;
    Ok(match format {
        FeaturePointFormat::FbakitXml => {
            let d = super::xml::parse_xml(text, path)?;
            FeaturePointFile {
                format,
                points: d.points,
                fapu: d.fapu,
                extras: FormatExtras::FbakitXml { units: d.units },
            }
        }
        FeaturePointFormat::XfaceFdp => {
            let x = super::xface::parse_xface(text, path)?;
            FeaturePointFile {
                format,
                points: x.to_set(),
                fapu: x.fapu,
                extras: FormatExtras::XfaceFdp(x),
            }
        }
        FeaturePointFormat::Csv => {
            let t = super::csv::parse_csv(text, path)?;
            FeaturePointFile {
                format,
                points: t.to_set(),
                fapu: None,
                extras: FormatExtras::Csv(t),
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_by_extension_then_content() {
        let d = |p: &str, t: &str| detect_format(Path::new(p), t);
        assert_eq!(d("a.csv", "<xfdp>"), Some(FeaturePointFormat::Csv));
        assert_eq!(
            d("a.fdp", "<?xml?>\n<xfdp>"),
            Some(FeaturePointFormat::XfaceFdp)
        );
        assert_eq!(d("a.xml", "<xfdp/>"), Some(FeaturePointFormat::XfaceFdp));
        assert_eq!(d("a.xml", "<x/>"), Some(FeaturePointFormat::FbakitXml));
        assert_eq!(
            d("a.txt", "<featurePoints version=\"1\"/>"),
            Some(FeaturePointFormat::FbakitXml)
        );
        assert_eq!(
            d("a", "fp,vertices\n2.1,1\n"),
            Some(FeaturePointFormat::Csv)
        );
        assert_eq!(d("a.obj", "v 1 2 3\n"), None);
        let e = parse_feature_points("v 1 2 3", Path::new("a.obj")).unwrap_err();
        assert!(e.to_string().contains("not a feature-point file"), "{e}");
        assert!(e.is_input_error());
    }

    #[test]
    fn every_format_fills_the_common_fields() {
        let f = parse_feature_points("fp,vertices\n2.1,3\n", Path::new("t.csv")).unwrap();
        assert_eq!(
            (f.format, f.points.len(), f.fapu),
            (FeaturePointFormat::Csv, 1, None)
        );
        let f = parse_feature_points(
            "<featurePoints version=\"1\" units=\"mm\"><point id=\"2.1\" x=\"0\" y=\"0\" z=\"0\"/></featurePoints>",
            Path::new("t.xml"),
        )
        .unwrap();
        assert_eq!(
            f.extras,
            FormatExtras::FbakitXml {
                units: Some("mm".into())
            }
        );
        let f = parse_feature_points(
            "<xfdp><head><fapu ENS0=\"1\" ES0=\"2\" IRISD0=\"3\" MNS0=\"4\" MW0=\"5\"/></head></xfdp>",
            Path::new("t.fdp"),
        )
        .unwrap();
        assert_eq!(f.fapu.unwrap().mw0, 5.0);
    }
}
