//! Whole-face cloning on the synthetic faces (ground truth available).

use std::time::Instant;

use fbakit::clone::eval::{compliance, ground_truth_error, self_clone_error};
use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::face::FaceModel;

fn alma() -> FaceModel {
    FaceModel::from_synth(&fbakit::synth::alma())
}
fn bruno() -> FaceModel {
    FaceModel::from_synth(&fbakit::synth::bruno())
}

#[test]
#[ignore = "measurement; run in release"]
fn measure_full_size() {
    let (a, b) = (alma(), bruno());
    for method in [Method::Fmc, Method::Rbf] {
        for rescale in [true, false] {
            if method == Method::Fmc && !rescale {
                continue;
            }
            let opts = CloneOptions {
                method,
                rbf_fapu_rescale: rescale,
                ..CloneOptions::default()
            };
            let t = Instant::now();
            let out = clone_face(&a, &b, &opts).unwrap();
            let el = t.elapsed().as_secs_f64();
            let gt = ground_truth_error(&out.face, &b).unwrap();
            let c = compliance(&out.face).unwrap();
            println!(
                "{method:?} rescale={rescale} a->b {el:.3}s gt all {:.2}% skin {:.2}% compliance worst {:.3} mean {:.4}",
                gt.mean_all, gt.mean_skin, c.worst, c.mean
            );
            println!("  timings {:?}", out.report.timings.steps);
            println!("  warnings {:?}", out.report.warnings);
            println!(
                "  align scale {} angle {} rms {}",
                out.report.alignment.scale,
                out.report.alignment.angle_degrees(),
                out.report.alignment_rms
            );
            let mut worst: Vec<_> = gt.keys.clone();
            worst.sort_by(|x, y| y.all.total_cmp(&x.all));
            println!("  worst keys {:?}", &worst[..8]);
            let mut cw = c.faps.clone();
            cw.sort_by(|x, y| y.along_error.total_cmp(&x.along_error));
            println!("  worst compliance {:?}", &cw[..6]);
            let out = clone_face(&b, &a, &opts).unwrap();
            let gt = ground_truth_error(&out.face, &a).unwrap();
            println!(
                "  b->a gt all {:.2}% skin {:.2}%",
                gt.mean_all, gt.mean_skin
            );
        }
        let t = Instant::now();
        let e = self_clone_error(&b, method).unwrap();
        println!(
            "{method:?} self-clone bruno {e:.2e}% in {:.3}s",
            t.elapsed().as_secs_f64()
        );
        println!(
            "{method:?} self-clone alma {:.2e}%",
            self_clone_error(&a, method).unwrap()
        );
    }
    let c = compliance(&b).unwrap();
    println!("bruno own compliance worst {} mean {}", c.worst, c.mean);
}
