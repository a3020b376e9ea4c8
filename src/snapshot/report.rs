//! The text reports of [`FaceDiff`] and [`FapDiff`]: the verdict and the worst first, then
//! one row per difference, worst first.

use std::fmt::Write;

use super::diff::{FaceDiff, TableDiff};
use super::fap_diff::{transmitted_only, FapDiff};

/// A figure in 4 significant digits (exponent form for the very small and large).
fn fig(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if !v.is_finite() {
        format!("{v}")
    } else if !(1e-3..1e5).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    }
}

fn table_label(t: &TableDiff) -> String {
    match t.fap {
        Some(n) => format!("{} (FAP {n})", t.table),
        None => t.table.clone(),
    }
}

/// The text report of a face comparison.
pub fn face_diff_text(d: &FaceDiff) -> String {
    let mut o = String::new();
    if let Some(problem) = &d.problem {
        let _ = writeln!(o, "NOT COMPARED: {} and {}: {problem}", d.a, d.b);
        return o;
    }
    let tol = &d.tolerance;
    let differing: Vec<&TableDiff> = d.differing_tables().collect();
    let verdict = if d.equal { "EQUAL" } else { "DIFFERENT" };
    let _ = writeln!(
        o,
        "{verdict}: {} and {}, tolerance {} ({} face units; face size {}), {} of {} tables differ",
        d.a,
        d.b,
        tol.given,
        fig(tol.absolute),
        fig(tol.face_size),
        differing.len(),
        d.tables.len()
    );
    if let Some(w) = d.worst_table() {
        let fapu = w
            .max_difference_fapu
            .map_or(String::new(), |f| format!(" = {} FAPU", fig(f)));
        let what = match w.only_in {
            Some(side) => format!("only in {}", side.to_string().to_uppercase()),
            None => format!(
                "max {}{fapu}, {} of {} moving vertices differ",
                fig(w.max_difference),
                w.differing_vertices,
                w.moving_vertices
            ),
        };
        let _ = writeln!(o, "worst table: {}: {what}", table_label(w));
    }
    if !differing.is_empty() {
        let _ = writeln!(
            o,
            "\n{:<28} {:>11} {:>10} {:>11} {:>10} {:>9} {:>9}  note",
            "table", "max", "max FAPU", "mean", "mean FAPU", "vertices", "rot deg"
        );
        for t in &differing {
            let note = match t.only_in {
                Some(side) => format!("only in {}", side.to_string().to_uppercase()),
                None => match (t.worst_vertex, t.worst_value) {
                    (Some(v), Some(p)) => format!("worst: vertex {v} at {p}"),
                    _ => String::new(),
                },
            };
            let opt = |v: Option<f64>| v.map_or("-".to_string(), fig);
            let _ = writeln!(
                o,
                "{:<28} {:>11} {:>10} {:>11} {:>10} {:>9} {:>9}  {note}",
                table_label(t),
                fig(t.max_difference),
                opt(t.max_difference_fapu),
                fig(t.mean_difference),
                opt(t.mean_difference_fapu),
                format!("{}/{}", t.differing_vertices, t.moving_vertices),
                fig(t.max_rotation_degrees),
            );
        }
        o.push('\n');
    }
    let n = &d.neutral;
    if n.equal {
        let _ = writeln!(o, "neutral: equal (max {})", fig(n.max_difference));
    } else {
        let _ = writeln!(
            o,
            "neutral: {} of {} vertices differ (max {}, mean {}); {} vs {} vertices",
            n.differing_vertices,
            n.vertices_a,
            fig(n.max_difference),
            fig(n.mean_difference),
            n.vertices_a,
            n.vertices_b
        );
        for t in &n.transforms {
            match t.only_in {
                Some(side) => {
                    let _ = writeln!(
                        o,
                        "  transform {}: only in {}",
                        t.name,
                        side.to_string().to_uppercase()
                    );
                }
                None => {
                    let _ = writeln!(
                        o,
                        "  transform {}: rotation {} deg, translation {}, scale {}",
                        t.name,
                        fig(t.rotation_degrees),
                        fig(t.translation),
                        fig(t.scale)
                    );
                }
            }
        }
    }
    if !n.meshes_only_in_a.is_empty() || !n.meshes_only_in_b.is_empty() {
        let _ = writeln!(
            o,
            "  meshes only in A: [{}]; only in B: [{}]",
            n.meshes_only_in_a.join(", "),
            n.meshes_only_in_b.join(", ")
        );
    }
    let fp = &d.feature_points;
    if fp.equal {
        let _ = writeln!(o, "feature points: equal (max {})", fig(fp.max_difference));
    } else {
        let list: Vec<String> = fp
            .differing
            .iter()
            .take(8)
            .map(|p| match p.only_in {
                Some(side) => format!("{} only in {}", p.id, side.to_string().to_uppercase()),
                None => format!("{} by {}", p.id, fig(p.difference)),
            })
            .collect();
        let more = fp.differing.len().saturating_sub(8);
        let _ = writeln!(
            o,
            "feature points: {} differ: {}{}",
            fp.differing.len(),
            list.join(", "),
            if more > 0 {
                format!(", and {more} more")
            } else {
                String::new()
            }
        );
    }
    if d.fapu.equal {
        o.push_str("FAPU: equal\n");
    } else {
        let list: Vec<String> = d
            .fapu
            .units
            .iter()
            .map(|u| {
                let v = |x: Option<f64>| x.map_or("-".to_string(), fig);
                format!("{} {} vs {}", u.unit.abbreviation(), v(u.a), v(u.b))
            })
            .collect();
        let _ = writeln!(o, "FAPU: differ: {}", list.join(", "));
    }
    o
}

/// The text report of a stream comparison.
pub fn fap_diff_text(d: &FapDiff) -> String {
    let mut o = String::new();
    let differing: Vec<_> = d.faps.iter().filter(|f| !f.equal).collect();
    let verdict = if d.equal { "EQUAL" } else { "DIFFERENT" };
    let _ = writeln!(
        o,
        "{verdict}: {} and {}, tolerance {} FAP units, {} of {} FAPs differ over {} compared frames",
        d.a,
        d.b,
        fig(d.tolerance),
        differing.len(),
        d.faps.len(),
        d.compared_frames
    );
    if let Some(w) = differing.first() {
        let _ = writeln!(
            o,
            "worst FAP: {} {}: max {} in {} frames{}",
            w.fap,
            w.name,
            fig(w.max_difference),
            w.differing_frames,
            w.worst_frame
                .map_or(String::new(), |f| format!(", worst at frame {f}"))
        );
    }
    if d.frame_rate_a != d.frame_rate_b {
        let _ = writeln!(o, "frame rate: {} vs {}", d.frame_rate_a, d.frame_rate_b);
    }
    let _ = writeln!(
        o,
        "frames: {} vs {} transmitted; {} only in A, {} only in B, {} with different masks{}",
        d.frames_a,
        d.frames_b,
        d.frames_only_in_a,
        d.frames_only_in_b,
        d.mask_differences,
        d.first_difference.map_or(String::new(), |f| format!(
            "; first difference at frame {f}"
        ))
    );
    if !differing.is_empty() {
        let _ = writeln!(
            o,
            "\n{:>3}  {:<24} {:>11} {:>8} {:>8}  note",
            "fap", "name", "max", "frames", "worst"
        );
        for f in differing {
            let note = match transmitted_only(f) {
                Some(side) => format!("sent only in {}", side.to_string().to_uppercase()),
                None => String::new(),
            };
            let _ = writeln!(
                o,
                "{:>3}  {:<24} {:>11} {:>8} {:>8}  {note}",
                f.fap,
                f.name,
                fig(f.max_difference),
                f.differing_frames,
                f.worst_frame.map_or("-".to_string(), |w| w.to_string()),
            );
        }
    }
    o
}

#[cfg(test)]
mod tests {
    use super::fig;

    #[test]
    fn figures_keep_four_digits() {
        assert_eq!(fig(0.0), "0");
        assert_eq!(fig(0.0123456), "0.01235");
        assert_eq!(fig(12.345), "12.35");
        assert_eq!(fig(1234.4), "1234");
        assert_eq!(fig(2.5e-5), "2.500e-5");
    }
}
