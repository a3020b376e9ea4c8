//! Scratch: fmc option variants on the synthetic faces.
use fbakit::clone::eval::{compliance, ground_truth_error, self_clone_error_with};
use fbakit::clone::face::{clone_face, CloneOptions, Method};
use fbakit::clone::fmc::{NormalisationMode, OverlapRule};
use fbakit::face::FaceModel;

fn main() {
    let a = FaceModel::from_synth(&fbakit::synth::alma());
    let b = FaceModel::from_synth(&fbakit::synth::bruno());
    for norm in [NormalisationMode::Anchored, NormalisationMode::Global] {
        for overlap in [OverlapRule::FrontMost, OverlapRule::NearestDepth] {
            for filter in [0.02f32, 0.0] {
                for lips in [true, false] {
                    let mut opts = CloneOptions::default();
                    opts.fmc.normalisation = norm;
                    opts.fmc.overlap = overlap;
                    opts.fmc.filter_support = filter;
                    opts.fmc.lip_separation = lips;
                    let e = self_clone_error_with(&a, &opts).unwrap();
                    let out = clone_face(&a, &b, &opts).unwrap();
                    let gt = ground_truth_error(&out.face, &b).unwrap();
                    let c = compliance(&out.face).unwrap();
                    println!("{norm:?} {overlap:?} filter {filter} lips {lips}: self {e:.6} %, gt all {:.2} skin {:.2}, compl worst {:.4} mean {:.4}", gt.mean_all, gt.mean_skin, c.worst, c.mean);
                }
            }
        }
    }
    let _ = Method::Fmc;
}
