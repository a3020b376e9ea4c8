//! Release-mode measurement of whole-face cloning on the synthetic faces (alma → bruno, ground
//! truth = bruno's own FAT): self-clone error per method, ground-truth error per key, FAP
//! compliance, alignment. Run with `cargo run --release --example clone_face_measure`
//! (`-- keys` also prints every key's error, `-- no-align` turns the alignment off).

use fbakit::clone::eval::{compliance, ground_truth_error, self_clone_error};
use fbakit::clone::face::{clone_face, CloneOptions, Method};

fn main() {
    let all_keys = std::env::args().any(|a| a == "keys");
    let align = !std::env::args().any(|a| a == "no-align");
    let a = fbakit::synth::alma().to_face_model();
    let b = fbakit::synth::bruno().to_face_model();
    for method in [Method::Fmc, Method::Rbf] {
        for (name, face) in [("alma", &a), ("bruno", &b)] {
            let e = self_clone_error(face, method).unwrap();
            println!("{method:?} self-clone {name}: {e:.3e} %");
        }
        let opts = CloneOptions {
            method,
            align,
            ..CloneOptions::default()
        };
        let out = clone_face(&a, &b, &opts).unwrap();
        let gt = ground_truth_error(&out.face, &b).unwrap();
        let c = compliance(&out.face).unwrap();
        println!(
            "{method:?} alma->bruno: ground truth all {:.2} % skin {:.2} %; compliance worst {:.4} mean {:.4}; align scale {:.6} angle {:.4} deg rms {:.4}",
            gt.mean_all,
            gt.mean_skin,
            c.worst,
            c.mean,
            out.report.alignment.scale,
            out.report.alignment.angle_degrees(),
            out.report.alignment_rms
        );
        let mut keys = gt.keys.clone();
        keys.sort_by(|x, y| y.skin.total_cmp(&x.skin));
        let shown = if all_keys { keys.len() } else { 12 };
        for k in &keys[..shown.min(keys.len())] {
            println!(
                "    {:<28} all {:8.2} % skin {:8.2} %",
                k.key, k.all, k.skin
            );
        }
        let mut cw = c.faps.clone();
        cw.sort_by(|x, y| y.along_error.total_cmp(&x.along_error));
        for f in &cw[..8.min(cw.len())] {
            println!(
                "    compliance {:<24} fp {:5} along {:.4} vector {:.4}",
                f.fap, f.feature_point, f.along_error, f.vector_error
            );
        }
        for w in &out.report.warnings {
            println!("    warning: {w}");
        }
    }
}
