use super::*;
use crate::clone::fixtures::candide;

#[test]
fn candide_self_clone_is_exact() {
    let Some(face) = candide(&[], 1, 512.0) else {
        return;
    };
    let out = clone_fit(
        &face.surface,
        &face.motions,
        &face.surface,
        &FitOptions::default(),
    )
    .unwrap();
    let mut worst: f32 = 0.0;
    let mut peak: f32 = 0.0;
    for (a, b) in face.motions.iter().zip(&out.motions) {
        let mut dense = vec![Vec3::ZERO; face.surface.positions.len()];
        for &(v, d) in &a.offsets {
            dense[v as usize] = d;
            peak = peak.max(d.length());
        }
        let mut got = vec![Vec3::ZERO; face.surface.positions.len()];
        for &(v, d) in &b.offsets {
            got[v as usize] = d;
        }
        for (x, y) in dense.iter().zip(&got) {
            worst = worst.max(x.distance(*y));
        }
    }
    assert!(worst <= 1e-5 * peak, "worst {worst} of peak {peak}");
}
