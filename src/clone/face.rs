//! Cloning a whole face: the source's FAT onto a target [`FaceModel`], skin by a surface method
//! ([`super::fmc`] or [`super::rbf`]) and rigid parts by transforms, after Pandžić 2003.
//!
//! # Steps (report timings use these names)
//!
//! 1. **`parts`** — each face's meshes are sorted into rigid parts from the feature points they
//!    hold ([`identify_parts`]): eyes (3.5, 3.6: the pupils), upper teeth (9.8, 9.10), lower
//!    teeth (9.9, 9.11), tongue (6.x); then meshes *connected* to a part (sharing a vertex
//!    position, quantised at 1e-5 of the face's size) join it unless they hold skin feature
//!    points or belong to another part (Pandžić's "connected meshes"). Meshes holding any other
//!    feature point, and meshes connected to those, are the deformable skin. Whatever is left
//!    (hair, hats) is listed and stays rigid with the head.
//! 2. **`align`** — a similarity (scale, rotation, translation; Umeyama's SVD solution) that
//!    puts the target's feature points onto the source's, least squares over every point both
//!    faces have. The target is cloned in that aligned frame (so a target modelled at another
//!    scale or turned sideways clones like one in the MPEG-4 frame) and displacements are
//!    mapped back by `Rᵀ/s`. A rotation under [`CloneOptions::align_snap_degrees`] (3°) is
//!    dropped and scale and translation refitted: upright faces of other proportions fit with
//!    a spurious tilt (0.94° for alma → bruno) that only turns FAP directions off the target's
//!    axes. [`CloneOptions::align`] turns the whole step off.
//! 3. **`surfaces`** — a [`CloneSurface`] per face: skin meshes placed by their transforms
//!    (`FaceModel::frames`), concatenated, polygons triangulated, coincident vertices welded
//!    (within 1e-6 of the face's size) so seams do not cut the surface — except inside the
//!    mouth box (between the lip corners, ±0.35 MNS0 around the lip line), where a closed
//!    mouth's upper and lower lip vertices coincide and must stay apart. Results on a welded
//!    vertex go back to every duplicate.
//! 4. **`motions`** — every table of the source FAT becomes one morph target per non-zero
//!    interval border ([`fat_to_morph_targets`]); skin displacements are turned into the face
//!    frame with each mesh's world 3×3 (a welded vertex takes the mean of its duplicates).
//! 5. The surface method's own steps (`fmc:*` or `rbf:*`).
//! 6. **`rescale`** (RBF only, [`CloneOptions::rbf_fapu_rescale`]) — the RBF method carries a
//!    motion through the Jacobian of its volume morph, not through FAPU ratios, so a FAP's
//!    feature point does not move by `value × FAPU × direction` on the target. With the
//!    option on (default), each motion of a low-level translation FAP is multiplied by one
//!    factor so its feature point's displacement has the length of the source's displacement
//!    × (target FAPU / source FAPU) of that FAP's unit. Off reproduces the paper.
//! 7. **`rigid`** — transforms ([`RigidReport`]): the target's part transforms are the lowest
//!    transforms enclosing each part's meshes; the head's encloses all face meshes. A part
//!    sharing its lowest transform with other meshes (a tongue under the jaw with the lower
//!    teeth is fine for the teeth, not for the tongue) gets a new transform, child of that one;
//!    a face without transforms gets a root `head`. Centres: eyes at their eyeball centre
//!    (least-squares sphere fit, bounding-box centre if the mesh is no sphere), head at 7.1;
//!    a transform the source rotates that has no centre (zero) gets the source's centre mapped
//!    through the alignment. Centres change with `translation` compensated, so the neutral
//!    pose does not move. Source `FaceDefTransform`s then map by role: rotations copy their
//!    axis (turned into the target's frame) and angle (AU is face independent); translations
//!    scale by target/source FAPU of the FAP's unit (high-level tables: ES for eyes, MNS for
//!    teeth and tongue, ENS for the head). Source tables that deform the tongue mesh
//!    (no surface method applies to it) become a rigid translation of the target's tongue
//!    transform by the FAPU-scaled displacement of the FAP's tongue feature point (the mean
//!    tongue displacement for high-level tables), as Pandžić does; tables whose tongue
//!    motion has no rigid equivalent (tongue roll) and deformations of other non-skin meshes
//!    (pupil dilation) are dropped with a warning.
//! 8. **`fat`** — per target skin mesh the face-frame displacements go back to the mesh frame
//!    (inverse world 3×3) and [`fat_from_morph_targets`] rebuilds the tables (multi-interval
//!    tables keep their borders); transform entries are appended. Every output number must be
//!    finite, or the clone fails.
//!
//! Rotations from the FAT are taken as composed after the neutral rotation (`R₀·ΔR`), so their
//! axes live in the transform's own rotated frame.
//!
//! # FMC settings
//!
//! Whole faces use [`face_fmc_options`], not the surface module's defaults: `Global` position
//! normalisation (`Anchored` folds the synthetic faces' lip region so the inner-lip FAPs 2.6/2.7
//! did not move at all), `NearestDepth` overlaps (inner layers map onto inner layers) and no
//! anti-aliasing filter (it smooths a self-clone: 0.005 % instead of 0).
//!
//! # Measured figures (release, `cargo run --release --example clone_face_measure`)
//!
//! Synthetic faces, alma → bruno against bruno's exact FAT ([`super::eval`]):
//!
//! | method | self-clone alma / bruno | ground truth all / skin | compliance worst / mean |
//! |---|---|---|---|
//! | fmc | 0 / 0 % | 30.6 / 24.0 % | 0 / 0 % |
//! | rbf (FAPU rescale) | 0 / 0 % | 31.5 / 24.0 % | 3.6 % / 0.51 % |
//!
//! Worst keys: the upper eyelid closures (bruno's eyes are proportionally different and neither
//! method knows the lid must follow the eyeball), nose and ear FAPs (rbf) and the lip FAPs.
//! Without the rotation snap (alignment turning bruno by 0.94°) fmc gave 33.7 / 26.9 % with
//! compliance worst 3.2 % (the jaw axis turned), rbf 33.3 / 25.8 % with worst 2.7 %.

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::time::Instant;

use glam::{Affine3A, DMat3, DVec3, Mat3, Vec3};
use serde::Serialize;

use super::fmc::{clone_fmc, FmcOptions, NormalisationMode, OverlapRule};
use super::rbf::{clone_rbf, RbfOptions};
use super::{CloneSurface, StepTimings, SurfaceCloneResult, SurfaceMotion};
use crate::error::{Error, Result};
use crate::face::{FaceFrames, FaceModel, FaceTransform};
use crate::fat::morph::{fat_from_morph_targets, fat_to_morph_targets, MorphMesh, MorphTarget};
use crate::fat::{FaceDefTransform, Fat, TableKey, TransformField};
use crate::fdp::{Fapu, FeaturePoint, FeaturePointSet};
use crate::mesh::find_coincident_vertices;
use crate::mesh::geometry::triangulate;
use crate::spec::{FapuKind, FeaturePointId};

/// Which surface method clones the skin.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Pandžić 2003 ([`super::fmc`]).
    #[default]
    Fmc,
    /// Fratarcangeli & Schaerf 2005 ([`super::rbf`]).
    Rbf,
}

impl Method {
    /// `fmc` or `rbf`.
    pub fn name(self) -> &'static str {
        match self {
            Method::Fmc => "fmc",
            Method::Rbf => "rbf",
        }
    }
}

/// Settings of [`clone_face`].
#[derive(Clone, Debug, PartialEq)]
pub struct CloneOptions {
    /// Surface method.
    pub method: Method,
    /// FMC settings (default: [`face_fmc_options`]).
    pub fmc: FmcOptions,
    /// RBF settings.
    pub rbf: RbfOptions,
    /// RBF only: rescale each low-level translation FAP's motion so its feature point moves
    /// FAPU-compliantly (module docs, step 6). Default on; off is the paper's behaviour.
    pub rbf_fapu_rescale: bool,
    /// Align the target onto the source by a similarity before cloning (step 2). Default on.
    pub align: bool,
    /// Alignment rotations up to this many degrees are dropped (upright faces of other
    /// proportions; [`Similarity::fit_snapped`]). Default 3°.
    pub align_snap_degrees: f64,
}

impl Default for CloneOptions {
    fn default() -> Self {
        CloneOptions {
            method: Method::Fmc,
            fmc: face_fmc_options(),
            rbf: RbfOptions::default(),
            rbf_fapu_rescale: true,
            align: true,
            align_snap_degrees: 3.0,
        }
    }
}

/// The FMC settings whole faces clone with (module docs, "FMC settings"): `Global` position
/// normalisation, nearest-depth overlap resolution and no anti-aliasing filter.
pub fn face_fmc_options() -> FmcOptions {
    FmcOptions {
        normalisation: NormalisationMode::Global,
        overlap: OverlapRule::NearestDepth,
        filter_support: 0.0,
        ..FmcOptions::default()
    }
}

/// A rigid part of a face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Part {
    /// Left eyeball (holds 3.5).
    LeftEye,
    /// Right eyeball (holds 3.6).
    RightEye,
    /// Upper teeth (9.8, 9.10).
    UpperTeeth,
    /// Lower teeth (9.9, 9.11).
    LowerTeeth,
    /// Tongue (6.1–6.4).
    Tongue,
}

impl Part {
    /// All parts, in the order roles are looked up.
    pub const ALL: [Part; 5] = [
        Part::LeftEye,
        Part::RightEye,
        Part::UpperTeeth,
        Part::LowerTeeth,
        Part::Tongue,
    ];

    /// Short name used for new transforms and messages.
    pub fn name(self) -> &'static str {
        match self {
            Part::LeftEye => "eye_l",
            Part::RightEye => "eye_r",
            Part::UpperTeeth => "teeth_upper",
            Part::LowerTeeth => "teeth_lower",
            Part::Tongue => "tongue",
        }
    }

    /// The feature points that identify the part.
    pub fn feature_points(self) -> Vec<FeaturePointId> {
        let labels: &[&str] = match self {
            Part::LeftEye => &["3.5"],
            Part::RightEye => &["3.6"],
            Part::UpperTeeth => &["9.8", "9.10"],
            Part::LowerTeeth => &["9.9", "9.11"],
            Part::Tongue => &["6.1", "6.2", "6.3", "6.4"],
        };
        labels.iter().map(|s| s.parse().expect("label")).collect()
    }

    /// The part a feature point identifies, if any.
    pub fn of_feature_point(id: FeaturePointId) -> Option<Part> {
        Part::ALL
            .into_iter()
            .find(|p| p.feature_points().contains(&id))
    }

    /// FAPU kind used to scale this part's translations for high-level tables.
    fn unit(self) -> FapuKind {
        match self {
            Part::LeftEye | Part::RightEye => FapuKind::Es,
            _ => FapuKind::Mns,
        }
    }
}

/// How a face's meshes split into skin and rigid parts (mesh indices).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FaceParts {
    /// The deformable surface.
    pub skin: Vec<usize>,
    /// Rigid parts.
    pub parts: BTreeMap<Part, Vec<usize>>,
    /// Meshes of neither (no feature point, not connected): rigid with the head.
    pub other: Vec<usize>,
}

/// Mesh and vertex of a feature point: its binding, else the nearest vertex of any mesh when
/// that is within `tol` of its position.
fn fp_mesh_vertex(
    face: &FaceModel,
    frames: &FaceFrames,
    id: FeaturePointId,
    tol: f32,
) -> Option<(usize, u32)> {
    if let Some(mv) = face.fp_vertex(id) {
        if face
            .meshes
            .get(mv.0)
            .is_some_and(|m| (mv.1 as usize) < m.mesh.positions.len())
        {
            return Some(mv);
        }
    }
    let p = face.feature_points.position(id)?;
    let mut best: Option<(usize, u32, f32)> = None;
    for (mi, m) in face.meshes.iter().enumerate() {
        let w = frames.meshes[mi];
        for (vi, &q) in m.mesh.positions.iter().enumerate() {
            let d = w.transform_point3(q).distance(p);
            if best.is_none_or(|b| d < b.2) {
                best = Some((mi, vi as u32, d));
            }
        }
    }
    best.filter(|b| b.2 <= tol).map(|b| (b.0, b.1))
}

fn face_diagonal(face: &FaceModel, frames: &FaceFrames) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for (mi, m) in face.meshes.iter().enumerate() {
        for &p in &m.mesh.positions {
            let q = frames.meshes[mi].transform_point3(p);
            if q.is_finite() {
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
    }
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        1.0
    }
}

/// Sorts a face's meshes into skin and rigid parts from its feature points (module docs,
/// step 1).
pub fn identify_parts(face: &FaceModel) -> FaceParts {
    let frames = face.frames();
    let diag = face_diagonal(face, &frames);
    let n = face.meshes.len();
    let mut part_of: Vec<Option<Part>> = vec![None; n];
    let mut has_skin_fp = vec![false; n];
    for fp in face.feature_points.iter() {
        let Some((mi, _)) = fp_mesh_vertex(face, &frames, fp.id, diag * 1e-4) else {
            continue;
        };
        match Part::of_feature_point(fp.id) {
            Some(p) => {
                if part_of[mi].is_none() {
                    part_of[mi] = Some(p);
                }
            }
            None => has_skin_fp[mi] = true,
        }
    }
    // A mesh holding skin points is skin even if a part point sits on it too (one-mesh heads).
    for mi in 0..n {
        if has_skin_fp[mi] {
            part_of[mi] = None;
        }
    }
    // Connectivity between meshes through coincident vertex positions.
    let q = (diag * 1e-5).max(f32::MIN_POSITIVE);
    let mut cells: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (mi, m) in face.meshes.iter().enumerate() {
        for &p in &m.mesh.positions {
            let w = frames.meshes[mi].transform_point3(p);
            if !w.is_finite() {
                continue;
            }
            let key = (
                (w.x / q).round() as i64,
                (w.y / q).round() as i64,
                (w.z / q).round() as i64,
            );
            let list = cells.entry(key).or_default();
            if !list.contains(&mi) {
                list.push(mi);
            }
        }
    }
    let mut adjacent: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for list in cells.values().filter(|l| l.len() > 1) {
        for &a in list {
            for &b in list {
                if a != b {
                    adjacent[a].insert(b);
                }
            }
        }
    }
    // Grow parts over connected meshes that hold no skin point and belong to nothing yet.
    let mut queue: Vec<usize> = (0..n).filter(|&m| part_of[m].is_some()).collect();
    while let Some(m) = queue.pop() {
        let p = part_of[m];
        for &o in &adjacent[m] {
            if part_of[o].is_none() && !has_skin_fp[o] {
                part_of[o] = p;
                queue.push(o);
            }
        }
    }
    let mut is_skin = has_skin_fp.clone();
    let mut queue: Vec<usize> = (0..n).filter(|&m| is_skin[m]).collect();
    while let Some(m) = queue.pop() {
        for &o in &adjacent[m] {
            if part_of[o].is_none() && !is_skin[o] {
                is_skin[o] = true;
                queue.push(o);
            }
        }
    }
    let mut out = FaceParts::default();
    for mi in 0..n {
        if let Some(p) = part_of[mi] {
            out.parts.entry(p).or_default().push(mi);
        } else if is_skin[mi] {
            out.skin.push(mi);
        } else {
            out.other.push(mi);
        }
    }
    out
}

/// A similarity `p ↦ s·R·p + t`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Similarity {
    /// Uniform scale.
    pub scale: f64,
    /// Rotation.
    pub rotation: glam::DQuat,
    /// Translation.
    pub translation: DVec3,
}

impl Default for Similarity {
    fn default() -> Self {
        Similarity::IDENTITY
    }
}

impl Similarity {
    /// The identity.
    pub const IDENTITY: Similarity = Similarity {
        scale: 1.0,
        rotation: glam::DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// Maps a point.
    pub fn point(&self, p: Vec3) -> Vec3 {
        (self.rotation * p.as_dvec3() * self.scale + self.translation).as_vec3()
    }

    /// Maps a displacement.
    pub fn vector(&self, v: Vec3) -> Vec3 {
        (self.rotation * v.as_dvec3() * self.scale).as_vec3()
    }

    /// Maps a displacement back (`Rᵀ v / s`).
    pub fn inverse_vector(&self, v: DVec3) -> DVec3 {
        self.rotation.inverse() * v / self.scale
    }

    /// Maps a point back.
    pub fn inverse_point(&self, p: DVec3) -> DVec3 {
        self.inverse_vector(p - self.translation)
    }

    /// Least-squares similarity taking `from[i]` onto `to[i]` (Umeyama 1991). Needs three
    /// non-collinear pairs.
    pub fn fit(from: &[DVec3], to: &[DVec3]) -> Result<Similarity> {
        let n = from.len().min(to.len());
        if n < 3 {
            return Err(Error::Invalid(format!(
                "aligning the faces needs at least 3 shared feature points, found {n}"
            )));
        }
        let mf = from[..n].iter().sum::<DVec3>() / n as f64;
        let mt = to[..n].iter().sum::<DVec3>() / n as f64;
        let mut cov = nalgebra::Matrix3::<f64>::zeros();
        let mut var_f = 0.0;
        for i in 0..n {
            let a = from[i] - mf;
            let b = to[i] - mt;
            var_f += a.length_squared();
            cov += nalgebra::Vector3::new(b.x, b.y, b.z)
                * nalgebra::Vector3::new(a.x, a.y, a.z).transpose();
        }
        cov /= n as f64;
        var_f /= n as f64;
        let svd = cov.svd(true, true);
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return Err(Error::Invalid("feature point alignment: SVD failed".into()));
        };
        let mut sv = svd.singular_values;
        // Rank check: collinear points leave the rotation undetermined.
        if var_f <= 0.0 || sv.iter().filter(|&&x| x > 1e-12 * sv.max()).count() < 2 {
            return Err(Error::Invalid(
                "feature point alignment: the shared feature points are collinear".into(),
            ));
        }
        let mut d = nalgebra::Matrix3::<f64>::identity();
        if (u * vt).determinant() < 0.0 {
            d[(2, 2)] = -1.0;
            sv[2] = -sv[2];
        }
        let r = u * d * vt;
        let scale = sv.sum() / var_f;
        let rm = DMat3::from_cols_array(&[
            r[(0, 0)],
            r[(1, 0)],
            r[(2, 0)],
            r[(0, 1)],
            r[(1, 1)],
            r[(2, 1)],
            r[(0, 2)],
            r[(1, 2)],
            r[(2, 2)],
        ]);
        let rotation = glam::DQuat::from_mat3(&rm).normalize();
        let translation = mt - rotation * mf * scale;
        if !scale.is_finite() || scale <= 0.0 || !translation.is_finite() {
            return Err(Error::Invalid(
                "feature point alignment gave a degenerate similarity".into(),
            ));
        }
        Ok(Similarity {
            scale,
            rotation,
            translation,
        })
    }

    /// [`Similarity::fit`], except that a rotation of at most `snap_degrees` is taken as no
    /// rotation at all: scale and translation are then refitted without it (least squares
    /// about the centroids, `s = Σ a·b / Σ |a|²`). Faces modelled upright in the MPEG-4 frame
    /// but with other proportions fit with a small spurious tilt (0.94° for the synthetic
    /// alma → bruno), which only turns FAP directions away from the target's axes.
    pub fn fit_snapped(from: &[DVec3], to: &[DVec3], snap_degrees: f64) -> Result<Similarity> {
        let full = Similarity::fit(from, to)?;
        if full.angle_degrees().abs() > snap_degrees {
            return Ok(full);
        }
        let n = from.len().min(to.len());
        let mf = from[..n].iter().sum::<DVec3>() / n as f64;
        let mt = to[..n].iter().sum::<DVec3>() / n as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let a = from[i] - mf;
            num += a.dot(to[i] - mt);
            den += a.length_squared();
        }
        let scale = num / den;
        if !scale.is_finite() || scale <= 0.0 {
            return Ok(full);
        }
        Ok(Similarity {
            scale,
            rotation: glam::DQuat::IDENTITY,
            translation: mt - mf * scale,
        })
    }

    /// Rotation angle in degrees.
    pub fn angle_degrees(&self) -> f64 {
        self.rotation.to_axis_angle().1.to_degrees()
    }
}

/// The skin of a face as a [`CloneSurface`], with the way back to its meshes.
#[derive(Clone, Debug)]
pub struct SkinSurface {
    /// The surface (in the frame it was built in).
    pub surface: CloneSurface,
    /// Skin meshes, in concatenation order.
    pub meshes: Vec<usize>,
    /// First concatenated index of each skin mesh.
    pub starts: Vec<usize>,
    /// Surface vertex of each concatenated vertex.
    pub welded: Vec<u32>,
    /// Concatenated vertices of each surface vertex (CSR: `members[member_start[w]..[w+1]]`).
    member_start: Vec<u32>,
    members: Vec<u32>,
}

impl SkinSurface {
    /// Concatenated vertices behind surface vertex `w`.
    pub fn duplicates(&self, w: u32) -> &[u32] {
        let a = self.member_start[w as usize] as usize;
        let b = self.member_start[w as usize + 1] as usize;
        &self.members[a..b]
    }

    /// `(mesh index, local vertex)` of a concatenated vertex.
    pub fn locate(&self, concat: u32) -> (usize, u32) {
        let k = self.starts.partition_point(|&s| s <= concat as usize) - 1;
        (self.meshes[k], concat - self.starts[k] as u32)
    }
}

/// Builds the [`CloneSurface`] of `skin` meshes, every position mapped by `frame` (module
/// docs, step 3).
pub fn build_skin_surface(
    face: &FaceModel,
    skin: &[usize],
    frame: &Similarity,
) -> Result<SkinSurface> {
    let frames = face.frames();
    let diag = face_diagonal(face, &frames);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut starts = Vec::new();
    for &mi in skin {
        let m = &face.meshes[mi].mesh;
        let start = positions.len();
        starts.push(start);
        positions.extend(
            m.positions
                .iter()
                .map(|&p| frame.point(frames.meshes[mi].transform_point3(p))),
        );
        let (tris, _) = triangulate(&m.positions, &m.polygons);
        triangles.extend(tris.iter().map(|t| t.map(|v| v + start as u32)));
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::Invalid(format!(
            "face `{}`: skin vertex {i} has a non-finite position",
            face.name
        )));
    }
    let mut fp_set = FeaturePointSet::new();
    let mut fp_positions = BTreeMap::new();
    for fp in face.feature_points.iter() {
        if let Some(p) = fp.position {
            let q = frame.point(p);
            fp_positions.insert(fp.id, q);
            fp_set.insert(FeaturePoint::at(fp.id, q));
        }
    }
    let fapu = Fapu::from_feature_points(&fp_set)
        .map_err(|e| Error::Invalid(format!("face `{}`: {e}", face.name)))?;
    // Weld, keeping the closed mouth apart.
    let eps = diag * frame.scale as f32 * 1e-6;
    let coincident = find_coincident_vertices(&positions, eps);
    let mouth = mouth_box(&fp_positions, &fapu);
    let mut rep = coincident.representative.clone();
    for cluster in &coincident.clusters {
        let p = positions[cluster[0] as usize];
        if mouth.is_some_and(|b| b.contains(p)) {
            for &v in cluster {
                rep[v as usize] = v;
            }
        }
    }
    let mut welded = vec![u32::MAX; positions.len()];
    let mut surface_positions = Vec::new();
    for i in 0..positions.len() {
        if rep[i] as usize == i {
            welded[i] = surface_positions.len() as u32;
            surface_positions.push(positions[i]);
        }
    }
    for i in 0..positions.len() {
        welded[i] = welded[rep[i] as usize];
    }
    let count = surface_positions.len();
    let mut member_start = vec![0u32; count + 1];
    for &w in &welded {
        member_start[w as usize + 1] += 1;
    }
    for i in 0..count {
        member_start[i + 1] += member_start[i];
    }
    let mut fill = member_start.clone();
    let mut members = vec![0u32; positions.len()];
    for (i, &w) in welded.iter().enumerate() {
        members[fill[w as usize] as usize] = i as u32;
        fill[w as usize] += 1;
    }
    let tris: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t: &[u32; 3]| t.map(|v| welded[v as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let mut fp_vertices = BTreeMap::new();
    let mesh_slot: HashMap<usize, usize> = skin.iter().enumerate().map(|(k, &m)| (m, k)).collect();
    for fp in face.feature_points.iter() {
        if let Some((mi, v)) = fp_mesh_vertex(face, &frames, fp.id, diag * 1e-4) {
            if let Some(&k) = mesh_slot.get(&mi) {
                if (v as usize) < face.meshes[mi].mesh.positions.len() {
                    fp_vertices.insert(fp.id, welded[starts[k] + v as usize]);
                }
            }
        }
    }
    Ok(SkinSurface {
        surface: CloneSurface {
            positions: surface_positions,
            triangles: tris,
            fp_vertices,
            fp_positions,
            fapu,
        },
        meshes: skin.to_vec(),
        starts,
        welded,
        member_start,
        members,
    })
}

#[derive(Clone, Copy)]
struct Box3 {
    lo: Vec3,
    hi: Vec3,
}

impl Box3 {
    fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }
}

fn mouth_box(fps: &BTreeMap<FeaturePointId, Vec3>, fapu: &Fapu) -> Option<Box3> {
    let get = |s: &str| {
        fps.get(&s.parse::<FeaturePointId>().expect("label"))
            .copied()
    };
    let (l, r) = (get("8.3")?, get("8.4")?);
    let mw = fapu.distances.mw0 as f32;
    let mns = fapu.distances.mns0 as f32;
    let lip_y = match (get("2.2"), get("2.3")) {
        (Some(a), Some(b)) => (a.y + b.y) / 2.0,
        _ => (l.y + r.y) / 2.0,
    };
    let z = l.z.min(r.z);
    Some(Box3 {
        lo: Vec3::new(l.x.min(r.x) - 0.1 * mw, lip_y - 0.35 * mns, z - 0.5 * mw),
        hi: Vec3::new(l.x.max(r.x) + 0.1 * mw, lip_y + 0.35 * mns, f32::INFINITY),
    })
}

/// Source morph targets as motions on a skin surface (face frame, welded).
fn surface_motions(
    face: &FaceModel,
    skin: &SkinSurface,
    targets: &[MorphTarget],
) -> Vec<SurfaceMotion> {
    let frames = face.frames();
    let slot: HashMap<&str, usize> = skin
        .meshes
        .iter()
        .enumerate()
        .map(|(k, &m)| (face.meshes[m].name.as_str(), k))
        .collect();
    let n = skin.surface.positions.len();
    targets
        .iter()
        .map(|t| {
            let mut sum: HashMap<u32, (DVec3, u32)> = HashMap::new();
            for mm in &t.meshes {
                let Some(&k) = slot.get(mm.mesh.as_str()) else {
                    continue;
                };
                let mi = skin.meshes[k];
                let lin = frames.meshes[mi].matrix3.as_dmat3();
                let len = face.meshes[mi].mesh.positions.len();
                for (&v, o) in mm.vertices.iter().zip(&mm.offsets) {
                    if (v as usize) < len {
                        let w = skin.welded[skin.starts[k] + v as usize];
                        let e = sum.entry(w).or_insert((DVec3::ZERO, 0));
                        e.0 += lin * *o;
                        e.1 += 1;
                    }
                }
            }
            let mut offsets: Vec<(u32, Vec3)> = sum
                .into_iter()
                .filter(|(w, _)| (*w as usize) < n)
                .map(|(w, (s, c))| (w, (s / c as f64).as_vec3()))
                .filter(|(_, d)| *d != Vec3::ZERO)
                .collect();
            offsets.sort_by_key(|o| o.0);
            SurfaceMotion {
                key: t.key,
                value: t.value,
                offsets,
            }
        })
        .collect()
}

/// What the rigid-part step found and did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RigidReport {
    /// Target transform used for each part (by name).
    pub part_transforms: BTreeMap<Part, String>,
    /// Target head transform.
    pub head_transform: Option<String>,
    /// Transforms fbakit created.
    pub created_transforms: Vec<String>,
    /// Centres installed: `(transform, centre in the face frame)`.
    pub installed_centres: Vec<(String, [f32; 3])>,
    /// Transform entries written to the target FAT.
    pub transform_entries: usize,
    /// Tables whose tongue deformation became a rigid tongue translation.
    pub rigid_tongue_tables: usize,
}

/// Everything [`clone_face`] reports besides the face.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CloneReport {
    /// Method used.
    pub method: Method,
    /// Per-step timings (surface steps prefixed `fmc:` / `rbf:`).
    pub timings: StepTimings,
    /// Figures from the surface method and the face layer.
    pub stats: BTreeMap<String, f64>,
    /// Warnings for the user.
    pub warnings: Vec<String>,
    /// Source parts.
    pub source_parts: FaceParts,
    /// Target parts.
    pub target_parts: FaceParts,
    /// Target → source alignment used.
    pub alignment: Similarity,
    /// RMS distance of the aligned target feature points to the source's, in source units.
    pub alignment_rms: f64,
    /// Skin vertices (welded) of source and target surfaces.
    pub surface_vertices: [usize; 2],
    /// Source morph targets cloned.
    pub motions: usize,
    /// Tables in the output FAT.
    pub tables: usize,
    /// RBF FAPU rescaling factors applied, per FAP name.
    pub fapu_rescale: BTreeMap<String, f64>,
    /// Rigid-part handling.
    pub rigid: RigidReport,
}

/// The target with its new FAT, and the report.
#[derive(Clone, Debug)]
pub struct CloneOutcome {
    /// The target face with the cloned FAT (and any transforms fbakit had to add).
    pub face: FaceModel,
    /// Timings, statistics, warnings.
    pub report: CloneReport,
}

/// Motions of the surface method on already built surfaces.
pub fn clone_surface(
    method: Method,
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    opts: &CloneOptions,
) -> Result<SurfaceCloneResult> {
    match method {
        Method::Fmc => clone_fmc(source, motions, target, &opts.fmc),
        Method::Rbf => clone_rbf(source, motions, target, &opts.rbf),
    }
}

fn shared_fps(source: &FaceModel, target: &FaceModel) -> (Vec<DVec3>, Vec<DVec3>) {
    let mut from = Vec::new();
    let mut to = Vec::new();
    for fp in target.feature_points.iter() {
        if let (Some(pt), Some(ps)) = (fp.position, source.feature_points.position(fp.id)) {
            if pt.is_finite() && ps.is_finite() {
                from.push(pt.as_dvec3());
                to.push(ps.as_dvec3());
            }
        }
    }
    (from, to)
}

/// Clones the source face's FAT onto the target face (module docs). The returned face is the
/// target with its new FAT and any transforms or centres the rigid parts needed.
///
/// Errors: missing required feature points (all listed), invalid geometry, a failing surface
/// method, or a non-finite number in the output.
pub fn clone_face(
    source: &FaceModel,
    target: &FaceModel,
    opts: &CloneOptions,
) -> Result<CloneOutcome> {
    let mut report = CloneReport {
        method: opts.method,
        ..CloneReport::default()
    };
    source.check_structure()?;
    target.check_structure()?;
    if source.fat.tables.is_empty() {
        return Err(Error::Invalid(format!(
            "source face `{}` has no FAT to clone",
            source.name
        )));
    }
    // 1. Parts.
    let clock = Instant::now();
    let sparts = identify_parts(source);
    let tparts = identify_parts(target);
    report.timings.push("parts", clock.elapsed().as_secs_f64());
    for (parts, name) in [(&sparts, "source"), (&tparts, "target")] {
        if parts.skin.is_empty() {
            return Err(Error::Invalid(format!(
                "{name} face has no skin mesh: no mesh holds a skin feature point"
            )));
        }
        if !parts.other.is_empty() {
            let face = if name == "source" { source } else { target };
            let names: Vec<&str> = parts
                .other
                .iter()
                .map(|&m| face.meshes[m].name.as_str())
                .collect();
            report.warnings.push(format!(
                "{name} meshes {} are neither skin nor a part; they stay rigid with the head",
                names.join(", ")
            ));
        }
    }
    // 2. Alignment.
    let clock = Instant::now();
    let alignment = if opts.align {
        let (from, to) = shared_fps(source, target);
        Similarity::fit_snapped(&from, &to, opts.align_snap_degrees)?
    } else {
        Similarity::IDENTITY
    };
    {
        let (from, to) = shared_fps(source, target);
        let ss: f64 = from
            .iter()
            .zip(&to)
            .map(|(f, t)| (alignment.point(f.as_vec3()).as_dvec3() - *t).length_squared())
            .sum();
        report.alignment_rms = (ss / from.len().max(1) as f64).sqrt();
    }
    report.alignment = alignment;
    report.timings.push("align", clock.elapsed().as_secs_f64());
    // 3. Surfaces.
    let clock = Instant::now();
    let ssurf = build_skin_surface(source, &sparts.skin, &Similarity::IDENTITY)?;
    let tsurf = build_skin_surface(target, &tparts.skin, &alignment)?;
    report.surface_vertices = [ssurf.surface.positions.len(), tsurf.surface.positions.len()];
    report
        .timings
        .push("surfaces", clock.elapsed().as_secs_f64());
    // 4. Motions.
    let clock = Instant::now();
    let targets = fat_to_morph_targets(&source.fat);
    let motions = surface_motions(source, &ssurf, &targets);
    report.motions = motions.len();
    report
        .timings
        .push("motions", clock.elapsed().as_secs_f64());
    // 5. Surface method (only motions that move the skin).
    let moving: Vec<SurfaceMotion> = motions
        .iter()
        .filter(|m| !m.offsets.is_empty())
        .cloned()
        .collect();
    let mut result = clone_surface(opts.method, &ssurf.surface, &moving, &tsurf.surface, opts)?;
    for (name, s) in &result.timings.steps {
        report
            .timings
            .push(&format!("{}:{name}", opts.method.name()), *s);
    }
    report.stats.extend(result.stats.clone());
    report.warnings.append(&mut result.warnings);
    // 6. FAPU rescale (RBF).
    if opts.method == Method::Rbf && opts.rbf_fapu_rescale {
        let clock = Instant::now();
        report.fapu_rescale =
            rescale_to_fapu(&ssurf.surface, &moving, &tsurf.surface, &mut result.motions);
        report
            .timings
            .push("rescale", clock.elapsed().as_secs_f64());
    }
    let cloned: HashMap<(TableKey, u64), &SurfaceMotion> = result
        .motions
        .iter()
        .map(|m| ((m.key, m.value.to_bits()), m))
        .collect();
    // 7. Rigid parts.
    let clock = Instant::now();
    let mut face = target.clone();
    face.fat = Fat::default();
    let rigid = RigidPlan::install(source, &sparts, &mut face, &tparts, &alignment, &mut report)?;
    report.timings.push("rigid", clock.elapsed().as_secs_f64());
    // 8. FAT.
    let clock = Instant::now();
    let frames = face.frames();
    let mut out_targets = Vec::with_capacity(targets.len());
    for t in &targets {
        let mut meshes = Vec::new();
        if let Some(m) = cloned.get(&(t.key, t.value.to_bits())) {
            meshes = back_to_meshes(&face, &frames, &tsurf, &alignment, m);
        }
        out_targets.push(MorphTarget {
            key: t.key,
            value: t.value,
            meshes,
            transforms: Vec::new(),
        });
    }
    let mut fat = fat_from_morph_targets(&out_targets)?;
    rigid.add_entries(
        source,
        &sparts,
        &targets,
        &face,
        &frames,
        &alignment,
        &tsurf,
        &mut fat,
        &mut report,
    );
    check_finite(&fat)?;
    report.tables = fat.tables.len();
    face.fat = fat;
    report.timings.push("fat", clock.elapsed().as_secs_f64());
    report.source_parts = sparts;
    report.target_parts = tparts;
    Ok(CloneOutcome { face, report })
}

fn check_finite(fat: &Fat) -> Result<()> {
    for t in &fat.tables {
        for m in &t.meshes {
            if m.displacements.iter().any(|d| !d.is_finite())
                || m.interval_borders.iter().any(|b| !b.is_finite())
            {
                return Err(Error::Invalid(format!(
                    "cloning produced a non-finite displacement for {} on mesh `{}`",
                    t.key, m.mesh
                )));
            }
        }
        for x in &t.transforms {
            if !x.rotation_axis.is_finite()
                || !x.rotation_angle.is_finite()
                || !x.scale.is_finite()
                || !x.translation.is_finite()
            {
                return Err(Error::Invalid(format!(
                    "cloning produced a non-finite transform entry for {} on `{}`",
                    t.key, x.transform
                )));
            }
        }
    }
    Ok(())
}

/// The feature point a low-level translation FAP is measured at, if both surfaces have it.
fn fap_fp(key: TableKey, a: &CloneSurface, b: &CloneSurface) -> Option<(FeaturePointId, FapuKind)> {
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

fn offset_at(m: &SurfaceMotion, v: u32) -> Vec3 {
    m.offsets
        .binary_search_by_key(&v, |o| o.0)
        .map_or(Vec3::ZERO, |i| m.offsets[i].1)
}

/// Step 6: scales each low-level translation motion so its feature point moves by the
/// FAPU-scaled source displacement. Returns the factors by FAP name.
fn rescale_to_fapu(
    source: &CloneSurface,
    motions: &[SurfaceMotion],
    target: &CloneSurface,
    out: &mut [SurfaceMotion],
) -> BTreeMap<String, f64> {
    let mut factors = BTreeMap::new();
    for (src, dst) in motions.iter().zip(out.iter_mut()) {
        let Some((fp, kind)) = fap_fp(src.key, source, target) else {
            continue;
        };
        let ds = offset_at(src, source.fp_vertices[&fp]).length() as f64;
        let dt = offset_at(dst, target.fp_vertices[&fp]).length() as f64;
        if ds <= 0.0 || dt <= ds * 1e-6 {
            continue;
        }
        let want = ds * target.fapu.unit(kind) / source.fapu.unit(kind);
        let k = want / dt;
        if !k.is_finite() {
            continue;
        }
        for o in &mut dst.offsets {
            o.1 *= k as f32;
        }
        factors.insert(format!("{}@{}", src.key.name(), src.value), k);
    }
    factors
}

/// A cloned surface motion as per-mesh offsets in each target skin mesh's local frame.
fn back_to_meshes(
    face: &FaceModel,
    frames: &FaceFrames,
    skin: &SkinSurface,
    frame: &Similarity,
    m: &SurfaceMotion,
) -> Vec<MorphMesh> {
    let inv: Vec<DMat3> = skin
        .meshes
        .iter()
        .map(|&mi| frames.meshes[mi].matrix3.as_dmat3().inverse())
        .collect();
    let mut per_mesh: Vec<Vec<(u32, DVec3)>> = vec![Vec::new(); skin.meshes.len()];
    for &(w, d) in &m.offsets {
        if w as usize >= skin.surface.positions.len() {
            continue;
        }
        let face_d = frame.inverse_vector(d.as_dvec3());
        for &c in skin.duplicates(w) {
            let k = skin.starts.partition_point(|&s| s <= c as usize) - 1;
            let local = c - skin.starts[k] as u32;
            per_mesh[k].push((local, inv[k] * face_d));
        }
    }
    per_mesh
        .into_iter()
        .enumerate()
        .filter(|(_, l)| !l.is_empty())
        .map(|(k, mut l)| {
            l.sort_by_key(|x| x.0);
            MorphMesh {
                mesh: face.meshes[skin.meshes[k]].name.clone(),
                vertices: l.iter().map(|x| x.0).collect(),
                offsets: l.iter().map(|x| x.1).collect(),
            }
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Rigid parts
// ---------------------------------------------------------------------------------------------

/// Role of a transform in cloning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Role {
    Part(Part),
    Head,
}

fn ancestors(face: &FaceModel, mut t: Option<usize>) -> Vec<usize> {
    let mut out = Vec::new();
    while let Some(i) = t {
        if out.contains(&i) || out.len() > face.transforms.len() {
            break;
        }
        out.push(i);
        t = face.transforms[i].parent;
    }
    out
}

/// Lowest transform enclosing all `meshes`.
fn lowest_enclosing(face: &FaceModel, meshes: &[usize]) -> Option<usize> {
    let first = *meshes.first()?;
    let chain = ancestors(face, face.meshes[first].transform);
    chain.into_iter().find(|&t| {
        meshes
            .iter()
            .all(|&m| ancestors(face, face.meshes[m].transform).contains(&t))
    })
}

fn encloses(face: &FaceModel, t: usize, mesh: usize) -> bool {
    ancestors(face, face.meshes[mesh].transform).contains(&t)
}

/// Roles of a face's transforms (without changing it).
fn roles(face: &FaceModel, parts: &FaceParts) -> (BTreeMap<Part, usize>, Option<usize>) {
    let all: Vec<usize> = parts
        .skin
        .iter()
        .chain(parts.parts.values().flatten())
        .copied()
        .collect();
    let head = lowest_enclosing(face, &all);
    let mut map = BTreeMap::new();
    for (&p, meshes) in &parts.parts {
        if let Some(t) = lowest_enclosing(face, meshes) {
            if Some(t) != head {
                map.insert(p, t);
            }
        }
    }
    (map, head)
}

fn unique_name(face: &FaceModel, base: &str) -> String {
    let mut name = base.to_string();
    let mut k = 1;
    while face.transform_index(&name).is_some() || face.mesh_index(&name).is_some() {
        k += 1;
        name = format!("{base}_{k}");
    }
    name
}

/// Moves `center` of transform `t` to the face-frame point `world`, compensating `translation`
/// so the transform's matrix (and the neutral pose) does not change.
pub fn install_center(face: &mut FaceModel, t: usize, world: Vec3) {
    let frames = face.frames();
    let c_new = frames.transforms[t].inverse().transform_point3(world);
    let tf = &mut face.transforms[t];
    let lin = crate::face::local_matrix(
        Vec3::ZERO,
        tf.rotation,
        tf.scale,
        tf.scale_orientation,
        Vec3::ZERO,
    )
    .matrix3;
    let dc = tf.center - c_new;
    tf.translation += dc - Mat3::from(lin) * dc;
    tf.center = c_new;
}

/// Least-squares sphere centre of points, or their bounding-box centre when they are no sphere.
fn eyeball_centre(points: &[Vec3]) -> Option<Vec3> {
    if points.is_empty() {
        return None;
    }
    let lo = points
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
    let hi = points
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
    let bbox = (lo + hi) / 2.0;
    if points.len() < 4 {
        return Some(bbox);
    }
    // |p|² = 2c·p + k, linear in (c, k); solved about the box centre for conditioning.
    let mut a = nalgebra::Matrix4::<f64>::zeros();
    let mut b = nalgebra::Vector4::<f64>::zeros();
    for &p in points {
        let q = (p - bbox).as_dvec3();
        let row = nalgebra::Vector4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0);
        a += row * row.transpose();
        b += row * q.length_squared();
    }
    let Some(x) = a.lu().solve(&b) else {
        return Some(bbox);
    };
    let c = DVec3::new(x[0], x[1], x[2]);
    let r2 = x[3] + c.length_squared();
    if r2.is_nan() || r2 <= 0.0 || !c.is_finite() {
        return Some(bbox);
    }
    let r = r2.sqrt();
    let rms = (points
        .iter()
        .map(|&p| ((p - bbox).as_dvec3().distance(c) - r).powi(2))
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    if rms > 0.1 * r {
        Some(bbox)
    } else {
        Some((c + bbox.as_dvec3()).as_vec3())
    }
}

struct RigidPlan {
    /// Target transform per source transform index.
    map: HashMap<usize, (Role, usize)>,
    /// Target tongue transform (for rigid tongue motion).
    tongue: Option<usize>,
}

impl RigidPlan {
    fn install(
        source: &FaceModel,
        sparts: &FaceParts,
        face: &mut FaceModel,
        tparts: &FaceParts,
        frame: &Similarity,
        report: &mut CloneReport,
    ) -> Result<RigidPlan> {
        let (sroles, shead) = roles(source, sparts);
        let sframes = source.frames();
        // Which source transforms the FAT drives, and which parts it deforms.
        let driven: HashSet<&str> = source
            .fat
            .tables
            .iter()
            .flat_map(|t| t.transforms.iter().map(|x| x.transform.as_str()))
            .collect();
        let rotated: HashSet<&str> = source
            .fat
            .tables
            .iter()
            .flat_map(|t| t.transforms.iter())
            .filter(|x| x.field == TransformField::Rotation)
            .map(|x| x.transform.as_str())
            .collect();
        let tongue_meshes: HashSet<&str> = sparts
            .parts
            .get(&Part::Tongue)
            .into_iter()
            .flatten()
            .map(|&m| source.meshes[m].name.as_str())
            .collect();
        let tongue_deformed = source.fat.tables.iter().any(|t| {
            t.meshes
                .iter()
                .any(|m| tongue_meshes.contains(m.mesh.as_str()))
        });
        let mut needed: BTreeSet<Part> = sroles
            .iter()
            .filter(|(_, &t)| driven.contains(source.transforms[t].name.as_str()))
            .map(|(&p, _)| p)
            .collect();
        if tongue_deformed {
            needed.insert(Part::Tongue);
        }
        let mut created = Vec::new();
        let mut structure_changed = false;
        // Head: lowest transform enclosing every face mesh, or a new root.
        let all: Vec<usize> = tparts
            .skin
            .iter()
            .chain(tparts.parts.values().flatten())
            .copied()
            .collect();
        let head = match lowest_enclosing(face, &all) {
            Some(h) => h,
            None => {
                let name = unique_name(face, "head");
                for t in &mut face.transforms {
                    t.parent = Some(t.parent.map_or(0, |p| p + 1));
                }
                for m in &mut face.meshes {
                    m.transform = Some(m.transform.map_or(0, |t| t + 1));
                }
                face.transforms
                    .insert(0, FaceTransform::new(name.clone(), None, Vec3::ZERO));
                created.push(name);
                structure_changed = true;
                0
            }
        };
        let mut part_tf: BTreeMap<Part, usize> = BTreeMap::new();
        for (&p, meshes) in &tparts.parts {
            let low = lowest_enclosing(face, meshes);
            let exclusive = low.is_some_and(|t| {
                t != head
                    && (0..face.meshes.len()).all(|m| {
                        !encloses(face, t, m)
                            || meshes.contains(&m)
                            || (p == Part::LowerTeeth
                                && tparts
                                    .parts
                                    .get(&Part::Tongue)
                                    .is_some_and(|x| x.contains(&m)))
                    })
            });
            if exclusive {
                part_tf.insert(p, low.expect("exclusive implies some"));
            } else if needed.contains(&p) {
                let parent = low.unwrap_or(head);
                let name = unique_name(face, &format!("{}_tf", p.name()));
                let frames = face.frames();
                let parent_world = frames.transforms[parent];
                face.transforms
                    .push(FaceTransform::new(name.clone(), Some(parent), Vec3::ZERO));
                let new_t = face.transforms.len() - 1;
                for &m in meshes {
                    // Re-express the mesh in the new transform's frame (= the parent's).
                    let to_new = parent_world.inverse() * frames.meshes[m];
                    if to_new != Affine3A::IDENTITY {
                        for q in &mut face.meshes[m].mesh.positions {
                            *q = to_new.transform_point3(*q);
                        }
                    }
                    face.meshes[m].transform = Some(new_t);
                }
                created.push(name);
                structure_changed = true;
                part_tf.insert(p, new_t);
            }
        }
        if structure_changed {
            face.scene = None;
            report.warnings.push(format!(
                "created transforms {}; the output is written as a new scene",
                created.join(", ")
            ));
        }
        // Centres.
        let mut installed = Vec::new();
        let frames = face.frames();
        for eye in [Part::LeftEye, Part::RightEye] {
            if let (Some(&t), Some(meshes)) = (part_tf.get(&eye), tparts.parts.get(&eye)) {
                let pts: Vec<Vec3> = meshes
                    .iter()
                    .flat_map(|&m| {
                        let w = frames.meshes[m];
                        face.meshes[m]
                            .mesh
                            .positions
                            .iter()
                            .map(move |&p| w.transform_point3(p))
                    })
                    .collect();
                if let Some(c) = eyeball_centre(&pts) {
                    install_center(face, t, c);
                    installed.push((face.transforms[t].name.clone(), c.to_array()));
                }
            }
        }
        match face.feature_points.position("7.1".parse().expect("label")) {
            Some(c) => {
                install_center(face, head, c);
                installed.push((face.transforms[head].name.clone(), c.to_array()));
            }
            None => report
                .warnings
                .push("target lacks 7.1 (neck base): the head keeps its centre of rotation".into()),
        }
        for p in [Part::UpperTeeth, Part::LowerTeeth, Part::Tongue] {
            let (Some(&tt), Some(&st)) = (part_tf.get(&p), sroles.get(&p)) else {
                continue;
            };
            let sname = source.transforms[st].name.as_str();
            if rotated.contains(sname) && face.transforms[tt].center == Vec3::ZERO {
                let s = &source.transforms[st];
                let parent = s
                    .parent
                    .map_or(Affine3A::IDENTITY, |q| sframes.transforms[q]);
                let sc = parent.transform_point3(s.translation + s.center);
                let c = frame.inverse_point(sc.as_dvec3()).as_vec3();
                install_center(face, tt, c);
                installed.push((face.transforms[tt].name.clone(), c.to_array()));
            }
        }
        // Source → target transform map.
        let mut map = HashMap::new();
        for (&p, &st) in &sroles {
            match part_tf.get(&p) {
                Some(&tt) => {
                    map.entry(st).or_insert((Role::Part(p), tt));
                }
                None => {
                    if driven.contains(source.transforms[st].name.as_str()) {
                        report.warnings.push(format!(
                            "target has no {} part: its transform motion is dropped",
                            p.name()
                        ));
                    }
                }
            }
        }
        if let Some(sh) = shead {
            map.entry(sh).or_insert((Role::Head, head));
        }
        report.rigid.part_transforms = part_tf
            .iter()
            .map(|(&p, &t)| (p, face.transforms[t].name.clone()))
            .collect();
        report.rigid.head_transform = Some(face.transforms[head].name.clone());
        report.rigid.created_transforms = created;
        report.rigid.installed_centres = installed;
        for p in Part::ALL {
            if sparts.parts.contains_key(&p) != tparts.parts.contains_key(&p) {
                let side = if sparts.parts.contains_key(&p) {
                    "target"
                } else {
                    "source"
                };
                report
                    .warnings
                    .push(format!("the {side} face has no {} mesh", p.name()));
            }
        }
        Ok(RigidPlan {
            map,
            tongue: part_tf.get(&Part::Tongue).copied(),
        })
    }

    /// Appends transform entries (mapped source entries and rigid tongue motion) to `fat`.
    #[allow(clippy::too_many_arguments)]
    fn add_entries(
        &self,
        source: &FaceModel,
        sparts: &FaceParts,
        targets: &[MorphTarget],
        face: &FaceModel,
        frames: &FaceFrames,
        frame: &Similarity,
        tsurf: &SkinSurface,
        fat: &mut Fat,
        report: &mut CloneReport,
    ) {
        let sframes = source.frames();
        let sfapu = source.fapu().ok();
        let tfapu = &tsurf.surface.fapu;
        let ratio = |key: TableKey, fallback: FapuKind| -> f64 {
            let kind = match key {
                TableKey::LowLevel(f) => f.info().fapu.unwrap_or(fallback),
                _ => fallback,
            };
            let kind = if kind == FapuKind::Au { fallback } else { kind };
            match &sfapu {
                Some(s) => tfapu.unit(kind) / s.unit(kind),
                None => frame.scale,
            }
        };
        // Frame in which a transform's rotation axis lives: parent world · neutral rotation.
        let axis_frame = |f: &FaceModel, fr: &FaceFrames, t: usize| -> DMat3 {
            let tf = &f.transforms[t];
            let parent = tf.parent.map_or(Affine3A::IDENTITY, |p| fr.transforms[p]);
            parent.matrix3.as_dmat3() * DMat3::from_quat(tf.rotation.as_dquat())
        };
        let parent_frame = |f: &FaceModel, fr: &FaceFrames, t: usize| -> DMat3 {
            f.transforms[t]
                .parent
                .map_or(DMat3::IDENTITY, |p| fr.transforms[p].matrix3.as_dmat3())
        };
        let mut entries = 0;
        let mut dropped_tf: BTreeSet<String> = BTreeSet::new();
        for table in &source.fat.tables {
            let Some(out) = fat.tables.iter_mut().find(|t| t.key == table.key) else {
                continue;
            };
            for x in &table.transforms {
                let Some(st) = source.transform_index(&x.transform) else {
                    continue;
                };
                let Some(&(role, tt)) = self.map.get(&st) else {
                    dropped_tf.insert(x.transform.clone());
                    continue;
                };
                let tname = face.transforms[tt].name.clone();
                let entry = match x.field {
                    TransformField::Rotation => {
                        let a = axis_frame(source, &sframes, st)
                            * x.rotation_axis.as_dvec3().normalize_or_zero();
                        let a_t = frame.rotation.inverse() * a;
                        let local =
                            (axis_frame(face, frames, tt).inverse() * a_t).normalize_or_zero();
                        FaceDefTransform::rotation(tname, local.as_vec3(), x.rotation_angle)
                    }
                    TransformField::Translation => {
                        let fallback = match role {
                            Role::Part(p) => p.unit(),
                            Role::Head => FapuKind::Ens,
                        };
                        let v = parent_frame(source, &sframes, st) * x.translation.as_dvec3();
                        // Aligned frame = source frame; the ratio uses the aligned target FAPU.
                        let v_t = frame.inverse_vector(v) * ratio(table.key, fallback);
                        let local = parent_frame(face, frames, tt).inverse() * v_t;
                        FaceDefTransform::translation(tname, local.as_vec3())
                    }
                    TransformField::Scale => FaceDefTransform {
                        transform: tname,
                        ..x.clone()
                    },
                };
                out.transforms.push(entry);
                entries += 1;
            }
        }
        if !dropped_tf.is_empty() {
            report.warnings.push(format!(
                "source transforms {} have no counterpart on the target; their motion is dropped",
                dropped_tf.into_iter().collect::<Vec<_>>().join(", ")
            ));
        }
        // Non-skin mesh deformations.
        let tongue_meshes: HashSet<&str> = sparts
            .parts
            .get(&Part::Tongue)
            .into_iter()
            .flatten()
            .map(|&m| source.meshes[m].name.as_str())
            .collect();
        let skin_meshes: HashSet<&str> = sparts
            .skin
            .iter()
            .map(|&m| source.meshes[m].name.as_str())
            .collect();
        let mut dropped: BTreeSet<String> = BTreeSet::new();
        let mut rigid_tongue = 0;
        let mut done: HashSet<TableKey> = HashSet::new();
        // One rigid translation per key, from its largest positive value (transforms are linear).
        let mut order: Vec<&MorphTarget> = targets.iter().collect();
        order.sort_by(|a, b| b.value.total_cmp(&a.value));
        for t in order {
            for mm in &t.meshes {
                let name = mm.mesh.as_str();
                if skin_meshes.contains(name) || mm.offsets.iter().all(|o| *o == DVec3::ZERO) {
                    continue;
                }
                if !tongue_meshes.contains(name) {
                    dropped.insert(format!("{} (mesh `{name}`)", t.key.name()));
                    continue;
                }
                if done.contains(&t.key) {
                    continue;
                }
                let Some(tt) = self.tongue else {
                    dropped.insert(format!("{} (no target tongue)", t.key.name()));
                    continue;
                };
                let Some(mi) = source.mesh_index(name) else {
                    continue;
                };
                let lin = sframes.meshes[mi].matrix3.as_dmat3();
                // Displacement of the FAP's tongue point, else the mean tongue displacement.
                let fp_vertex = match t.key {
                    TableKey::LowLevel(f) => f.info().feature_points.iter().find_map(|&id| {
                        source.fp_vertex(id).filter(|(m, _)| *m == mi).map(|x| x.1)
                    }),
                    _ => None,
                };
                let d = match fp_vertex {
                    Some(v) => mm
                        .vertices
                        .iter()
                        .position(|&x| x == v)
                        .map_or(DVec3::ZERO, |k| lin * mm.offsets[k]),
                    None => {
                        mm.offsets.iter().map(|o| lin * *o).sum::<DVec3>() / mm.offsets.len() as f64
                    }
                };
                let size = mm.offsets.iter().map(|o| o.length()).fold(0.0, f64::max);
                if d.length() <= 1e-3 * size || d.length() == 0.0 {
                    dropped.insert(format!(
                        "{} (tongue motion is no translation)",
                        t.key.name()
                    ));
                    done.insert(t.key);
                    continue;
                }
                let v_t = frame.inverse_vector(d) * ratio(t.key, FapuKind::Mns) / t.value;
                let local = parent_frame(face, frames, tt).inverse() * v_t;
                if let Some(out) = fat.tables.iter_mut().find(|x| x.key == t.key) {
                    out.transforms.push(FaceDefTransform::translation(
                        face.transforms[tt].name.clone(),
                        local.as_vec3(),
                    ));
                    entries += 1;
                    rigid_tongue += 1;
                }
                done.insert(t.key);
            }
        }
        if !dropped.is_empty() {
            report.warnings.push(format!(
                "non-skin deformations without a rigid equivalent are dropped: {}",
                dropped.into_iter().collect::<Vec<_>>().join(", ")
            ));
        }
        report.rigid.transform_entries = entries;
        report.rigid.rigid_tongue_tables = rigid_tongue;
    }
}

#[cfg(test)]
mod tests;
