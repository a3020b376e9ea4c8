//! The RBF method's FAPU rescale (module docs of [`super`], step 6) and the guard every
//! method's cloned motions pass afterwards: a FAP whose own feature point barely moves, or
//! whose rescale factor is far outside the faces' FAPU ratio, is repaired by a direct
//! nearest-vertex transfer (or, failing that, a local move of its feature point) or dropped,
//! and reported ([`FapFailure`]).

use std::collections::BTreeMap;

use glam::{DQuat, Quat, Vec3};
use serde::Serialize;

use crate::clone::{CloneSurface, SurfaceMotion};
use crate::fat::TableKey;
use crate::mesh::geometry::adjacency;
use crate::mesh::VertexIndex;
use crate::spec::{FapuKind, FeaturePointId};

/// A cloned feature point moving less than this share of its expected motion has failed.
const MIN_MOTION_SHARE: f64 = 0.05;
/// Largest accepted ratio (either way) between a rescale factor and the FAPU ratio, and
/// between the cloned and the expected motion of a feature point.
const MAX_FACTOR_RATIO: f64 = 4.0;

/// A cloned FAP motion that failed the guard.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FapFailure {
    /// Table key name (`raise_r_cornerlip`).
    pub fap: String,
    /// The motion's FAP value (interval border).
    pub value: f64,
    /// Why it failed.
    pub reason: String,
    /// The rescale factor it would have needed (expected / cloned feature-point motion;
    /// infinite, `null` in JSON, when the feature point did not move at all).
    pub factor: f64,
    /// `true`: replaced by a direct transfer (nearest vertex, else the feature point's own
    /// move) that passed the check; `false`: the FAP's table was dropped.
    pub repaired: bool,
    /// Which repair passed (`None`: dropped).
    pub repair: Option<FapRepair>,
}

/// The repair that passed the guard's check.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FapRepair {
    /// Each target vertex takes the displacement of its nearest source vertex.
    DirectTransfer,
    /// The FAP's feature point moves by the source's displacement there, its surroundings
    /// with it.
    FeaturePoint,
}

/// The feature point a low-level translation FAP is measured at, if both surfaces have it.
pub(super) fn fap_fp(
    key: TableKey,
    a: &CloneSurface,
    b: &CloneSurface,
) -> Option<(FeaturePointId, FapuKind)> {
    let TableKey::LowLevel(f) = key else {
        return None;
    };
    let info = f.info();
    let kind = info.fapu?;
    if kind == FapuKind::Au || info.direction().is_none() {
        return None;
    }
    info.feature_points
        .iter()
        .find(|id| a.fp_vertices.contains_key(id) && b.fp_vertices.contains_key(id))
        .map(|&id| (id, kind))
}

/// Target / source FAPU of `kind` (1 when the source's is zero).
fn fapu_ratio(source: &CloneSurface, target: &CloneSurface, kind: FapuKind) -> f64 {
    let s = source.fapu.unit(kind);
    if s > 0.0 && s.is_finite() {
        target.fapu.unit(kind) / s
    } else {
        1.0
    }
}

/// Source and cloned displacement lengths of a motion's feature point and the FAPU ratio of
/// its unit: `(ds, dt, r)`; `None` for motions the guard cannot measure.
fn measure(
    source: &CloneSurface,
    src: &SurfaceMotion,
    target: &CloneSurface,
    dst: &SurfaceMotion,
) -> Option<(f64, f64, f64)> {
    let (fp, kind) = fap_fp(src.key, source, target)?;
    let ds = src.offset_at(source.fp_vertices[&fp]).length() as f64;
    let dt = dst.offset_at(target.fp_vertices[&fp]).length() as f64;
    (ds > 0.0).then_some((ds, dt, fapu_ratio(source, target, kind)))
}

/// Step 6: scales each low-level translation motion so its feature point moves by the
/// FAPU-scaled source displacement. Returns the factors by FAP name. Factors the guard would
/// reject (far outside the FAPU ratio, or a feature point that does not move) are not
/// applied: [`guard_motions`] repairs those motions.
pub(super) fn rescale_to_fapu(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, f64> {
    let mut factors = BTreeMap::new();
    for (src, dst) in motions.iter().zip(out.iter_mut()) {
        let Some((ds, dt, r)) = measure(source, src, target, dst) else {
            continue;
        };
        let k = ds * r / dt;
        if !k.is_finite() || check(ds, dt, r, Some(k)).is_some() {
            continue;
        }
        for o in &mut dst.offsets {
            o.1 *= k as f32;
        }
        factors.insert(format!("{}@{}", src.key.name(), src.value), k);
    }
    factors
}

/// Reach of the compliance gain ([`gain_to_fapu`]), in ES0: about one feature (a lid, a
/// brow, half the lips) around the FAP's feature point.
const GAIN_REACH_ES0: f32 = 0.5;
/// Compliance errors under this share of the expected motion are left alone.
const GAIN_TOLERANCE: f64 = 0.01;
/// Largest gain (either way). Wider than the guard's [`MAX_FACTOR_RATIO`]: a cartoon's lip
/// corner or brow registered beside a real head's moving peak leaves the feature point
/// 1/4–1/7 of its motion (bruno ↔ `ict`), which the smooth gain field repairs without a
/// crease (the normal-turn ratios did not change); the guard's bound is for whole motions.
/// Beyond it the gain adds the difference instead of scaling ([`gain_to_fapu`]).
const MAX_GAIN: f64 = 10.0;

/// Wendland's C² bump `(1 − x)⁴ (4x + 1)` on `[0, 1]`, 0 beyond: 1 at the centre, flat at
/// both ends.
pub(super) fn bump(x: f32) -> f32 {
    if x >= 1.0 {
        0.0
    } else {
        let y = 1.0 - x.max(0.0);
        y * y * y * y * (4.0 * x.max(0.0) + 1.0)
    }
}

/// Largest turn (radians, 45°) the gain gives a feature point's motion towards the wanted
/// direction; a motion further off (or needing a gain outside `[1/10, 10]`) is corrected by
/// adding the difference instead (see [`gain_to_fapu`]).
const MAX_GAIN_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// Target vertices within `reach` of `centre` along mesh edges, with that distance (Dijkstra,
/// stopped at `reach`); vertices marked in `closed` (indexed by vertex; shorter or empty:
/// none) are not entered. Along edges, not straight: a bump around an upper-lip point does
/// not jump the open slit onto the lower lip, nor from a lid onto the other lid.
pub(super) fn edge_ball(
    positions: &[Vec3],
    adj: &[Vec<u32>],
    centre: u32,
    reach: f32,
    closed: &[bool],
) -> Vec<(u32, f32)> {
    use std::cmp::Reverse;
    use std::collections::{BinaryHeap, HashMap};
    let mut best: HashMap<u32, f32> = HashMap::from([(centre, 0.0)]);
    // Non-negative floats order like their bits.
    let mut heap = BinaryHeap::from([Reverse((0f32.to_bits(), centre))]);
    let mut done = Vec::new();
    while let Some(Reverse((bits, v))) = heap.pop() {
        let d = f32::from_bits(bits);
        if best.get(&v).is_some_and(|&b| b < d) {
            continue;
        }
        done.push((v, d));
        for &w in adj.get(v as usize).map_or(&[][..], |a| a.as_slice()) {
            if closed.get(w as usize).copied().unwrap_or(false) {
                continue;
            }
            let nd = d + positions[v as usize].distance(positions[w as usize]);
            if nd < reach && best.get(&w).is_none_or(|&b| nd < b) {
                best.insert(w, nd);
                heap.push(Reverse((nd.to_bits(), w)));
            }
        }
    }
    done
}

/// Makes each low-level translation FAP's feature point move by the FAPU-scaled source
/// displacement (the compliance MPEG-4 asks for), smoothly, within `R` = [`GAIN_REACH_ES0`]
/// × ES0 of the target's feature point `f`, with `φ` = [`bump`] of the distance over `R`. The
/// wanted displacement `w` is the source's × the target/source FAPU of the FAP's unit, turned
/// by the alignment's rotation `turn` (target → source frame): FAP directions live in each
/// face's own axes, so a source moving its chin down and back asks the target to move down
/// and back along *its* axes, not along the source's (bruno's 3.15° alignment tipped the
/// chin's large backward motion into the target's y, 10 % of the FAP, before). With `d_f`
/// the cloned feature-point displacement:
///
/// - when `d_f` is within [`MAX_GAIN_TURN`] of `w` and `k = ‖w‖/‖d_f‖` within `[1/10, 10]`,
///   the motion `d` becomes `g·Q·d`, the gain `g = 1 + (k − 1)·φ` and `Q` the turn about
///   `d_f × w` by `θ·φ` (`θ` the angle from `d_f` to `w`), `φ` of the straight distance:
///   still vertices stay still;
/// - otherwise (a coarse target whose registration read the wrong side of a feature, so its
///   point moves the other way or barely: CANDIDE's brows and lips under the ICT head's FAPs)
///   `d` becomes `d + (w − d_f)·φ`, `φ` of the distance along mesh edges ([`edge_ball`]), so
///   the added motion does not jump an open slit. (Along edges for the gain too moved the
///   CANDIDE sparse → dense known-FAT case from 1.33 to 1.36 % median: the edge paths of a
///   dense mesh are longer than the straight line, which narrows the bump.)
///
/// At `f` the motion is exactly `w`; beyond `R` it is untouched; in between the field is
/// smooth, so the motion stays as smooth as it was. A registration that put the feature
/// point off the source's peak (a cartoon's brow onto a real one) so no longer leaves the FAP
/// weak, without a uniform rescale of the whole motion. Motions within 1 % of `w`, and those
/// whose feature point barely moves (the guard's business), are left alone. The target
/// follows its source: a source whose own motion is not compliant is cloned as it is (a
/// self-clone stays exact). Returns, by FAP name and value, the least-squares factor
/// `(w·d_f)/(d_f·d_f)` of each corrected motion.
pub(super) fn gain_to_fapu(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    out: &mut [SurfaceMotion],
    turn: DQuat,
) -> BTreeMap<String, f64> {
    let mut gains = BTreeMap::new();
    let reach = GAIN_REACH_ES0 * target.fapu.distances.es0 as f32;
    if !(reach > 0.0 && reach.is_finite()) {
        return gains;
    }
    let adj = adjacency(target.positions.len(), &target.triangles);
    for (src, dst) in motions.iter().zip(out.iter_mut()) {
        let Some((fp, kind)) = fap_fp(src.key, source, target) else {
            continue;
        };
        let (sv, tv) = (source.fp_vertices[&fp], target.fp_vertices[&fp]);
        let r = fapu_ratio(source, target, kind);
        let want = turn * (src.offset_at(sv).as_dvec3() * r);
        let got = dst.offset_at(tv).as_dvec3();
        let (wl, gl) = (want.length(), got.length());
        if !(wl > 0.0 && want.is_finite() && gl >= MIN_MOTION_SHARE * wl) {
            continue;
        }
        if (want - got).length() <= GAIN_TOLERANCE * wl {
            continue;
        }
        let angle = got.angle_between(want);
        let k = wl / gl;
        if angle <= MAX_GAIN_TURN && (1.0 / MAX_GAIN..=MAX_GAIN).contains(&k) {
            let axis = got.cross(want).normalize_or_zero().as_vec3();
            let angle = if axis == Vec3::ZERO {
                0.0
            } else {
                angle as f32
            };
            let centre = target.positions[tv as usize];
            for (v, d) in &mut dst.offsets {
                let w = bump(target.positions[*v as usize].distance(centre) / reach);
                if w == 0.0 {
                    continue;
                }
                let q = Quat::from_axis_angle(axis, angle * w);
                *d = q * *d * (1.0 + (k as f32 - 1.0) * w);
            }
        } else {
            let fix = (want - got).as_vec3();
            let mut dense: BTreeMap<u32, Vec3> = dst.offsets.iter().copied().collect();
            for (v, x) in edge_ball(&target.positions, &adj, tv, reach, &[]) {
                *dense.entry(v).or_insert(Vec3::ZERO) += fix * bump(x / reach);
            }
            dst.offsets = dense
                .into_iter()
                .filter(|(_, d)| *d != Vec3::ZERO)
                .collect();
        }
        gains.insert(
            format!("{}@{}", src.key.name(), src.value),
            want.dot(got) / got.length_squared(),
        );
    }
    gains
}

/// Why a motion whose feature point moved `dt` (source `ds`, FAPU ratio `r`, rescale factor
/// `k` if one applies) fails, or `None`.
fn check(ds: f64, dt: f64, r: f64, k: Option<f64>) -> Option<String> {
    let want = ds * r;
    if !(dt.is_finite() && want.is_finite()) {
        return Some("non-finite motion".into());
    }
    if dt < MIN_MOTION_SHARE * want {
        return Some(format!(
            "its feature point moves {:.2} % of the expected motion",
            100.0 * dt / want
        ));
    }
    if let Some(k) = k {
        // The method may or may not have carried the FAPU ratio already: accept factors near
        // 1 or near r.
        let (lo, hi) = (r.min(1.0) / MAX_FACTOR_RATIO, r.max(1.0) * MAX_FACTOR_RATIO);
        if !(lo..=hi).contains(&k) {
            return Some(format!(
                "FAPU rescale factor {k:.4} outside [{lo:.4}, {hi:.4}] (FAPU ratio {r:.4})"
            ));
        }
    } else if dt > MAX_FACTOR_RATIO * want {
        return Some(format!(
            "its feature point moves {:.0} % of the expected motion",
            100.0 * dt / want
        ));
    }
    None
}

/// The guard (module docs of [`super`], step 6): checks every cloned low-level translation
/// motion against its source; a failing one is replaced by a direct transfer (each target
/// vertex takes the source displacement of its nearest source vertex in the aligned frame,
/// times the FAPU ratio), else by [`feature_point_transfer`], and re-checked; if that fails
/// too, every motion of that FAP is emptied and the key returned among the dropped ones.
/// `rescaled` says whether step 6 ran (its factor is then part of the check).
pub(super) fn guard_motions(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    out: &mut [SurfaceMotion],
    rescaled: bool,
) -> Vec<FapFailure> {
    let mut failures = Vec::new();
    let mut nearest: Option<Vec<u32>> = None;
    for (src, dst) in motions.iter().zip(out.iter_mut()) {
        let Some((ds, dt, r)) = measure(source, src, target, dst) else {
            continue;
        };
        let k = ds * r / dt;
        let Some(reason) = check(ds, dt, r, rescaled.then_some(k)) else {
            continue;
        };
        let map = nearest.get_or_insert_with(|| nearest_source_vertices(source, target));
        let passes = |m: &SurfaceMotion| {
            measure(source, src, target, m)
                .is_some_and(|(ds2, dt2, r2)| check(ds2, dt2, r2, None).is_none())
        };
        let mut repaired = direct_transfer(src, map, r as f32);
        let mut repair = FapRepair::DirectTransfer;
        if !passes(&repaired) {
            if let Some(m) = feature_point_transfer(source, src, target) {
                repaired = m;
                repair = FapRepair::FeaturePoint;
            }
        }
        let ok = passes(&repaired);
        *dst = if ok {
            repaired
        } else {
            SurfaceMotion {
                offsets: Vec::new(),
                ..dst.clone()
            }
        };
        failures.push(FapFailure {
            fap: src.key.name(),
            value: src.value,
            reason,
            factor: k,
            repaired: ok,
            repair: ok.then_some(repair),
        });
    }
    // A dropped FAP loses every interval, not only the failing one.
    for f in failures.iter().filter(|f| !f.repaired) {
        for dst in out.iter_mut().filter(|m| m.key.name() == f.fap) {
            dst.offsets.clear();
        }
    }
    failures
}

/// The last repair, for a feature point that the method and the direct transfer both keep
/// still: a coarse target can hold a lid point and an eye corner on one vertex (a sphere's
/// few vertices around the eye), or its lid point can lie beyond the source's surface and
/// nearest a still source vertex (CANDIDE-3's right upper lid under the ICT head: its
/// `close_t_r_eyelid` was dropped, so that eye never blinked). The FAP's feature point moves
/// by the source's displacement there times the FAPU ratio, the target vertices around it
/// with it by [`bump`] out to half the distance to the nearest other vertex holding a feature
/// point (at most [`GAIN_REACH_ES0`] ES0: short of the other lid across the slit): the lid
/// still closes where its point is. `None` for a point still in the source.
fn feature_point_transfer(
    source: &CloneSurface,
    src: &SurfaceMotion,
    target: &CloneSurface,
) -> Option<SurfaceMotion> {
    let (fp, kind) = fap_fp(src.key, source, target)?;
    let (sv, tv) = (source.fp_vertices[&fp], target.fp_vertices[&fp]);
    let want = src.offset_at(sv) * fapu_ratio(source, target, kind) as f32;
    let centre = *target.positions.get(tv as usize)?;
    if want == Vec3::ZERO || !want.is_finite() {
        return None;
    }
    let reach = target
        .fp_vertices
        .values()
        .filter(|&&v| v != tv)
        .filter_map(|&v| target.positions.get(v as usize))
        .map(|p| p.distance(centre))
        .filter(|&d| d > 0.0)
        .fold(
            2.0 * GAIN_REACH_ES0 * target.fapu.distances.es0 as f32,
            f32::min,
        )
        / 2.0;
    if !(reach > 0.0 && reach.is_finite()) {
        return None;
    }
    let offsets = target
        .positions
        .iter()
        .enumerate()
        .filter_map(|(v, p)| {
            let w = bump(p.distance(centre) / reach);
            (w > 0.0).then_some((v as u32, want * w))
        })
        .collect();
    Some(SurfaceMotion {
        key: src.key,
        value: src.value,
        offsets,
    })
}

/// The nearest source surface vertex of every target surface vertex (both in the aligned
/// frame).
fn nearest_source_vertices(source: &CloneSurface, target: &CloneSurface) -> Vec<u32> {
    let index = VertexIndex::new(&source.positions);
    target
        .positions
        .iter()
        .map(|&p| index.nearest_vertex(p).map_or(u32::MAX, |n| n.0))
        .collect()
}

/// The source motion carried to target vertices through `nearest`, scaled by `ratio`.
fn direct_transfer(src: &SurfaceMotion, nearest: &[u32], ratio: f32) -> SurfaceMotion {
    let offsets = nearest
        .iter()
        .enumerate()
        .filter_map(|(t, &s)| {
            let d = src.offset_at(s);
            (s != u32::MAX && d != Vec3::ZERO).then_some((t as u32, d * ratio))
        })
        .collect();
    SurfaceMotion {
        key: src.key,
        value: src.value,
        offsets,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdp::{Fapu, FapuDistances};
    use crate::spec::FapId;
    use glam::DVec3;

    fn surface(positions: Vec<Vec3>, scale: f64) -> CloneSurface {
        let d = FapuDistances {
            irisd0: scale,
            es0: scale,
            ens0: scale,
            mns0: scale,
            mw0: scale,
        };
        CloneSurface {
            positions,
            triangles: vec![[0, 1, 2]],
            fp_vertices: [(FeaturePointId::new(2, 5).unwrap(), 0)].into(),
            fp_positions: BTreeMap::new(),
            fapu: Fapu::from_distances(d).unwrap(),
        }
    }

    fn motion(offsets: Vec<(u32, Vec3)>) -> SurfaceMotion {
        SurfaceMotion {
            // raise_r_cornerlip: measured at 2.5, MNS.
            key: TableKey::LowLevel(FapId::new(13).unwrap()),
            value: 512.0,
            offsets,
        }
    }

    #[test]
    fn a_still_feature_point_is_repaired_not_rescaled_by_a_huge_factor() {
        let tri = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let (s, t) = (surface(tri.clone(), 1.0), surface(tri, 2.0));
        let src = vec![motion(vec![(0, Vec3::new(0.0, 0.1, 0.0))])];
        let mut out = vec![motion(vec![
            (0, Vec3::new(0.0, 1e-6, 0.0)),
            (1, Vec3::new(0.0, 0.1, 0.0)),
        ])];
        let factors = rescale_to_fapu(&s, &src, &t, &mut out);
        assert!(factors.is_empty(), "{factors:?}");
        let f = guard_motions(&s, &src, &t, &mut out, true);
        assert_eq!(f.len(), 1);
        assert!(f[0].repaired && f[0].factor > 1e5, "{f:?}");
        assert_eq!(f[0].repair, Some(FapRepair::DirectTransfer));
        // Direct transfer: 2.5 takes its own source motion × the MNS ratio 2.
        assert!(out[0].offset_at(0).distance(Vec3::new(0.0, 0.2, 0.0)) < 1e-6);
        assert_eq!(out[0].offset_at(1), Vec3::ZERO);
    }

    #[test]
    fn a_feature_point_alone_on_a_still_source_vertex_is_moved_with_its_surroundings() {
        let s = surface(vec![Vec3::ZERO, Vec3::X, Vec3::Y], 1.0);
        // The target's 2.5 (vertex 0) and its surroundings lie by the source's still vertex
        // 1: the method and a direct transfer leave them still.
        let at = |dx: f32, dy: f32| Vec3::X + Vec3::new(dx, dy, 0.0);
        let mut t = surface(
            vec![at(0.0, 0.0), at(0.0, 0.1), at(0.0, 0.3), at(0.2, 0.0)],
            1.0,
        );
        t.triangles = vec![[0, 1, 3], [1, 2, 3]];
        // Another feature point (2.3) 0.3 up, across a slit: the repair reaches half way.
        t.fp_vertices.insert(FeaturePointId::new(2, 3).unwrap(), 2);
        let src = vec![motion(vec![(0, Vec3::new(0.0, 0.1, 0.0))])];
        let mut out = vec![motion(vec![(3, Vec3::new(0.0, 1e-4, 0.0))])];
        let f = guard_motions(&s, &src, &t, &mut out, false);
        assert!(f.len() == 1 && f[0].repaired, "{f:?}");
        assert_eq!(f[0].repair, Some(FapRepair::FeaturePoint));
        // 2.5 takes its source motion, vertex 1 (0.1 away, reach 0.15) part of it, 2.3 and
        // vertex 3 (0.2 away) nothing.
        assert_eq!(out[0].offset_at(0), Vec3::new(0.0, 0.1, 0.0));
        let part = out[0].offset_at(1).y;
        assert!(part > 0.0 && part < 0.1, "{part}");
        assert_eq!(out[0].offset_at(2), Vec3::ZERO);
        assert_eq!(out[0].offset_at(3), Vec3::ZERO);
    }

    #[test]
    fn a_feature_point_sharing_its_vertex_is_moved_alone() {
        let s = surface(vec![Vec3::ZERO, Vec3::X, Vec3::Y], 1.0);
        // The target's 2.5 sits on the source's still vertex 1 and shares its vertex with
        // 2.3: the method and the direct transfer leave it still.
        let mut t = surface(vec![Vec3::X, Vec3::ZERO, Vec3::Y], 1.0);
        t.fp_vertices.insert(FeaturePointId::new(2, 3).unwrap(), 0);
        let src = vec![motion(vec![(0, Vec3::new(0.0, 0.1, 0.0))])];
        let mut out = vec![motion(vec![(1, Vec3::new(0.0, 0.1, 0.0))])];
        let f = guard_motions(&s, &src, &t, &mut out, false);
        assert!(f.len() == 1 && f[0].repaired, "{f:?}");
        assert_eq!(f[0].repair, Some(FapRepair::FeaturePoint));
        // 2.5 takes its source motion; the others, a unit away (beyond half an ES0), stay.
        assert_eq!(out[0].offset_at(0), Vec3::new(0.0, 0.1, 0.0));
        assert_eq!(out[0].offsets.len(), 1);
    }

    #[test]
    fn the_gain_makes_the_feature_point_compliant_and_leaves_far_vertices() {
        // ES0 = 1: the gain reaches half a unit around 2.5 (vertex 0 at the origin).
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y * 0.25];
        let (s, t) = (surface(pos.clone(), 1.0), surface(pos, 1.0));
        let src = vec![motion(vec![(0, Vec3::new(0.0, 0.1, 0.0))])];
        let mut out = vec![motion(vec![
            (0, Vec3::new(0.0, 0.05, 0.0)),
            (1, Vec3::new(0.0, 0.05, 0.0)),
            (2, Vec3::new(0.0, 0.05, 0.0)),
        ])];
        let gains = gain_to_fapu(&s, &src, &t, &mut out, DQuat::IDENTITY);
        assert!(
            (gains.values().next().unwrap() - 2.0).abs() < 1e-6,
            "{gains:?}"
        );
        assert!(out[0].offset_at(0).distance(Vec3::new(0.0, 0.1, 0.0)) < 1e-6);
        assert_eq!(out[0].offset_at(1), Vec3::new(0.0, 0.05, 0.0));
        let mid = out[0].offset_at(2).y;
        assert!(mid > 0.05 && mid < 0.1, "{mid}");
        // A compliant motion is left alone.
        let before = out.clone();
        assert!(gain_to_fapu(&s, &src, &t, &mut out, DQuat::IDENTITY).is_empty());
        assert_eq!(out, before);
    }

    #[test]
    fn the_gain_turns_the_wanted_motion_by_the_alignment_and_adds_what_it_cannot_scale() {
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y * 0.25];
        let (s, t) = (surface(pos.clone(), 1.0), surface(pos, 1.0));
        // The source moves its point down and back; the target is aligned by 10° about x.
        let src = vec![motion(vec![(0, Vec3::new(0.0, -0.1, -0.2))])];
        let turn = DQuat::from_rotation_x(10f64.to_radians());
        let want = (turn * DVec3::new(0.0, -0.1, -0.2)).as_vec3();
        let mut out = vec![motion(vec![(0, Vec3::new(0.0, -0.1, -0.2))])];
        gain_to_fapu(&s, &src, &t, &mut out, turn);
        assert!(out[0].offset_at(0).distance(want) < 1e-6);
        // A feature point moving the wrong way is brought to the wanted motion by adding the
        // difference, which fades out along the edge to vertex 2 and misses vertex 1.
        let mut out = vec![motion(vec![
            (0, Vec3::new(0.0, 0.1, 0.2)),
            (1, Vec3::new(0.0, 0.1, 0.2)),
        ])];
        let gains = gain_to_fapu(&s, &src, &t, &mut out, DQuat::IDENTITY);
        assert!(gains.values().next().unwrap() < &0.0, "{gains:?}");
        assert!(out[0].offset_at(0).distance(Vec3::new(0.0, -0.1, -0.2)) < 1e-6);
        assert_eq!(out[0].offset_at(1), Vec3::new(0.0, 0.1, 0.2));
        let mid = out[0].offset_at(2);
        assert!(mid.y < 0.0 && mid.y > -0.1, "{mid}");
    }

    #[test]
    fn a_compliant_motion_passes() {
        let tri = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let (s, t) = (surface(tri.clone(), 1.0), surface(tri, 1.5));
        let src = vec![motion(vec![(0, Vec3::new(0.0, 0.1, 0.0))])];
        let mut out = vec![motion(vec![(0, Vec3::new(0.0, 0.12, 0.0))])];
        let factors = rescale_to_fapu(&s, &src, &t, &mut out);
        assert!((factors.values().next().unwrap() - 1.25).abs() < 1e-4);
        assert!(guard_motions(&s, &src, &t, &mut out, true).is_empty());
    }
}
