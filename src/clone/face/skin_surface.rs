//! The skin of a face as one welded [`CloneSurface`], with the way back to its meshes (module
//! docs of [`super`], step 3).

use std::collections::{BTreeMap, HashMap};

use glam::Vec3;

use super::parts::{face_diagonal, fp_mesh_vertex};
use super::Similarity;
use crate::clone::CloneError;
use crate::clone::CloneSurface;
use crate::error::Result;
use crate::face::{FaceFrames, FaceModel};
use crate::fdp::{Fapu, FeaturePoint, FeaturePointSet};
use crate::mesh::components::UnionFind;
use crate::mesh::find_coincident_vertices;
use crate::mesh::geometry::triangulate;
use crate::spec::FeaturePointId;

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
    /// Whether each concatenated vertex is a corner of some polygon. A point in no polygon
    /// is invisible (CANDIDE-3 keeps unused copies of its midline points); cloned motion
    /// never goes to it, as no FAT would move it.
    pub referenced: Vec<bool>,
    /// The concatenated meshes' triangles (before welding).
    concat_triangles: Vec<[u32; 3]>,
    /// The skin meshes' polygons, in concatenation order.
    polygons: Vec<crate::mesh::Polygons>,
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
    build_skin_surface_like(face, skin, frame, None)
}

/// Share of polygons that may differ between two meshes that are still one mesh (a rig's
/// identities exported apart: ICT's identity sample splits 4 of its 24 418 quads along the
/// other diagonal).
const DIFFERENT_POLYGONS: f64 = 0.001;

/// Whether two polygon lists are one mesh's: as many polygons, each with the same corners in
/// the same place of the list (in any order), but for [`DIFFERENT_POLYGONS`] of them.
pub(super) fn same_polygons(a: &crate::mesh::Polygons, b: &crate::mesh::Polygons) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let sorted = |p: &[u32]| {
        let mut v = p.to_vec();
        v.sort_unstable();
        v
    };
    let differ = a
        .iter()
        .zip(b.iter())
        .filter(|(p, q)| p.len() != q.len() || sorted(p) != sorted(q))
        .count();
    differ as f64 <= DIFFERENT_POLYGONS * a.len() as f64
}

/// [`build_skin_surface`], welded and triangulated exactly as `like` when both skins are
/// one mesh (the same vertex count and polygons, but for one in a thousand polygons: a rig's
/// identities exported apart may split a few quads along the other diagonal): a face and its
/// reshaped or rescaled copy may have seams that coincide on one and not on the other, or
/// quads convex on one and not on the other, and the same welding and triangles keep their
/// surfaces one mesh (so [`fit`](crate::clone::fit) matches them vertex to vertex).
pub fn build_skin_surface_like(
    face: &FaceModel,
    skin: &[usize],
    frame: &Similarity,
    like: Option<&SkinSurface>,
) -> Result<SkinSurface> {
    let frames = face.frames();
    let diag = face_diagonal(face, &frames);
    let (positions, mut triangles, starts) = concatenate_skin(face, &frames, skin, frame);
    let polygons: Vec<crate::mesh::Polygons> = skin
        .iter()
        .map(|&mi| face.meshes[mi].mesh.polygons.clone())
        .collect();
    // One mesh with `like`: its triangulation too (a quad convex on one face and not on the
    // other would be split along another diagonal, and the two would no longer be one mesh).
    if let Some(l) = like {
        let same = l.polygons.len() == polygons.len()
            && l.polygons
                .iter()
                .zip(&polygons)
                .all(|(a, b)| same_polygons(a, b));
        if l.welded.len() == positions.len() && same {
            triangles.clone_from(&l.concat_triangles);
        }
    }
    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
        return Err(CloneError::NonFiniteSkin {
            face: face.name.clone(),
            vertex: i,
        }
        .into());
    }
    let (fp_positions, fapu) = framed_feature_points(face, frame)?;
    let mut referenced = vec![false; positions.len()];
    for &v in triangles.iter().flatten() {
        referenced[v as usize] = true;
    }
    // Weld, keeping the closed mouth apart.
    let eps = diag * frame.scale as f32 * 1e-6;
    let mouth = mouth_box(&fp_positions, &fapu);
    let (welded, surface_positions) = match like {
        Some(l) if l.welded.len() == positions.len() && l.concat_triangles == triangles => {
            let count = l.welded.iter().map(|&w| w as usize + 1).max().unwrap_or(0);
            let mut surface_positions = vec![Vec3::ZERO; count];
            // Each surface vertex at its first member in a polygon (copies on the other
            // face need not coincide here: an unused copy does not follow a reshape).
            let mut placed = vec![false; count];
            for pass_referenced in [true, false] {
                for (i, &w) in l.welded.iter().enumerate() {
                    if !placed[w as usize] && (referenced[i] || !pass_referenced) {
                        placed[w as usize] = true;
                        surface_positions[w as usize] = positions[i];
                    }
                }
            }
            (l.welded.clone(), surface_positions)
        }
        _ => {
            let slit = mouth.map(|b| (b, closed_slit_middle(&fp_positions, &fapu)));
            weld_outside_mouth(&positions, &triangles, &starts, eps, slit)
        }
    };
    let (member_start, members) = duplicate_lists(&welded, surface_positions.len());
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
        referenced,
        concat_triangles: triangles,
        polygons,
        member_start,
        members,
    })
}

/// The skin meshes placed in the face frame, mapped by `frame` and concatenated:
/// `(positions, triangles, first index of each mesh)`.
fn concatenate_skin(
    face: &FaceModel,
    frames: &FaceFrames,
    skin: &[usize],
    frame: &Similarity,
) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<usize>) {
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
    (positions, triangles, starts)
}

/// The face's placed feature points mapped by `frame`, and the face's FAPU in the frame's
/// units. The FAPU are component differences along the face's axes (MNS0 = 9.15.y − 2.2.y),
/// so for a face modelled upright they are measured on its own points, then scaled: measured
/// on turned points they would read part of another axis (CANDIDE aligned onto the ICT head
/// turns 6.65°, and its nose–mouth z offset made every cloned FAP 3.9 % off its FAPU). A
/// frame turning more than [`Similarity::keeps_own_axes`] allows measures them on the turned
/// points.
fn framed_feature_points(
    face: &FaceModel,
    frame: &Similarity,
) -> Result<(BTreeMap<FeaturePointId, Vec3>, Fapu)> {
    let mut fp_set = FeaturePointSet::new();
    let mut fp_positions = BTreeMap::new();
    let upright = frame.keeps_own_axes();
    for fp in face.feature_points.iter() {
        if let Some(p) = fp.position {
            let q = frame.point(p);
            fp_positions.insert(fp.id, q);
            fp_set.insert(FeaturePoint::at(fp.id, if upright { p } else { q }));
        }
    }
    let fapu_error = |e| CloneError::Fapu {
        face: face.name.clone(),
        source: Box::new(e),
    };
    let own = Fapu::from_feature_points(&fp_set).map_err(fapu_error)?;
    let d = own.distances;
    let s = if upright { frame.scale } else { 1.0 };
    let fapu = Fapu::from_distances(crate::fdp::FapuDistances {
        irisd0: d.irisd0 * s,
        es0: d.es0 * s,
        ens0: d.ens0 * s,
        mns0: d.mns0 * s,
        mw0: d.mw0 * s,
    })
    .map_err(|e| fapu_error(e.into()))?;
    Ok((fp_positions, fapu))
}

/// Welds vertices within `eps` of each other. Inside the mouth box (`slit.0`) a closed
/// mouth's upper and lower lips coincide and must stay apart, while seam duplicates there (a
/// UV seam down the lips, the border between a skin and a mouth primitive) must not:
/// coincident vertices in the box are welded unless one's polygons lie all above it and the
/// other's all below (the opposite lips of the closed slit; `y` is up in the frame cloning
/// works in) — or they come from different meshes (`starts`: each mesh's first vertex), which
/// meet there along a border: ICT's lips end on its mouth socket, the lip's polygons above the
/// lower lip's inner edge and the socket's below; as two glTF primitives they parted there (a
/// crack) while the one OBJ mesh holds one vertex.
///
/// Locally a UV seam along the lip's edge on its socket, inside one primitive, is exactly such
/// a slit (two boundary fans, one above and one below, continuing each other: a closed slit
/// cut in a sheet is a seam, bruno's lips too), so what tells them apart is where the chain
/// runs: a closed slit is the mouth's opening and runs through the middle of the inner lip
/// line (2.2/2.3, `slit.1`), while a seam on the socket lies behind the lips. Vertices kept
/// apart are chained by the edges joining them; only a chain passing within its reach of
/// that middle stays apart, every other is welded (ICT's lips on their socket, split at UV
/// seams in one glTF primitive, parted by 11 % of `open_jaw`'s peak). Without the middle
/// (no 2.2/2.3) every chain stays apart. Returns the surface vertex of every input vertex and
/// the surface positions.
fn weld_outside_mouth(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    starts: &[usize],
    eps: f32,
    slit: Option<(Box3, Option<(Vec3, f32)>)>,
) -> (Vec<u32>, Vec<Vec3>) {
    let mouth = slit.map(|s| s.0);
    let middle = slit.and_then(|s| s.1);
    let mesh_of = |v: u32| starts.partition_point(|&s| s <= v as usize);
    let coincident = find_coincident_vertices(positions, eps);
    let mut rep = coincident.representative.clone();
    let in_mouth: Vec<&Vec<u32>> = coincident
        .clusters
        .iter()
        .filter(|c| mouth.is_some_and(|b| b.contains(positions[c[0] as usize])))
        .collect();
    if !in_mouth.is_empty() {
        let side = lip_sides(positions, triangles);
        // The clusters kept apart, by index in `in_mouth`, to chain them after.
        let mut apart: Vec<usize> = Vec::new();
        for (ci, cluster) in in_mouth.iter().enumerate() {
            // Members join the first group whose side is compatible, else the first group
            // holding no vertex of their own mesh; a group takes the side of a sided member.
            let mut groups: Vec<(u32, LipSide, Vec<usize>)> = Vec::new();
            for &v in cluster.iter() {
                let (s, m) = (side[v as usize], mesh_of(v));
                let join = groups
                    .iter()
                    .position(|(_, g, _)| g.compatible(s))
                    .or_else(|| groups.iter().position(|(_, _, ms)| !ms.contains(&m)));
                match join {
                    Some(k) => {
                        let (r, g, ms) = &mut groups[k];
                        rep[v as usize] = *r;
                        if *g == LipSide::Both {
                            *g = s;
                        }
                        ms.push(m);
                    }
                    None => {
                        rep[v as usize] = v;
                        groups.push((v, s, vec![m]));
                    }
                }
            }
            if groups.len() > 1 {
                apart.push(ci);
            }
        }
        if let Some((middle, reach)) = middle {
            for chain in chains(&apart, &in_mouth, triangles, positions.len()) {
                let at_middle = chain
                    .iter()
                    .any(|&ci| positions[in_mouth[ci][0] as usize].distance(middle) <= reach);
                if !at_middle {
                    for &ci in &chain {
                        for &v in in_mouth[ci] {
                            rep[v as usize] = coincident.representative[v as usize];
                        }
                    }
                }
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
    (welded, surface_positions)
}

/// The clusters `apart` (indices into `clusters`) joined into chains: two are in one chain
/// when an edge of `triangles` joins a member of one to a member of the other.
fn chains(
    apart: &[usize],
    clusters: &[&Vec<u32>],
    triangles: &[[u32; 3]],
    vertex_count: usize,
) -> Vec<Vec<usize>> {
    let mut slot = vec![u32::MAX; vertex_count];
    for (k, &ci) in apart.iter().enumerate() {
        for &v in clusters[ci] {
            slot[v as usize] = k as u32;
        }
    }
    let mut sets = UnionFind::new(apart.len());
    for t in triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (sa, sb) = (slot[a as usize], slot[b as usize]);
            if sa != u32::MAX && sb != u32::MAX {
                sets.union(sa, sb);
            }
        }
    }
    let (label, count) = sets.labels();
    let mut by = vec![Vec::new(); count];
    for (k, &ci) in apart.iter().enumerate() {
        by[label[k] as usize].push(ci);
    }
    by
}

/// The middle of a closed mouth's inner lip line (between 2.2 and 2.3) and how near a chain
/// of lip vertices kept apart must pass to be its slit: a tenth of MNS0 (a closed slit holds
/// 2.2 and 2.3 on its own vertices; ICT's lip/socket seam passes 0.34 MNS0 away).
fn closed_slit_middle(fps: &BTreeMap<FeaturePointId, Vec3>, fapu: &Fapu) -> Option<(Vec3, f32)> {
    let (a, b) = (
        fps.get(&FeaturePointId::FP_2_2)?,
        fps.get(&FeaturePointId::FP_2_3)?,
    );
    Some(((*a + *b) / 2.0, 0.1 * fapu.distances.mns0 as f32))
}

/// Where a vertex's polygons lie, vertically.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LipSide {
    /// All above it (an upper lip's edge).
    Above,
    /// All below it.
    Below,
    /// Both, or no polygon.
    Both,
}

impl LipSide {
    /// Whether two duplicates with these sides may be one vertex.
    fn compatible(self, other: LipSide) -> bool {
        !matches!(
            (self, other),
            (LipSide::Above, LipSide::Below) | (LipSide::Below, LipSide::Above)
        )
    }
}

/// The [`LipSide`] of every vertex from its triangles' other corners (a tenth of the fan's
/// height of tolerance).
fn lip_sides(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<LipSide> {
    let mut range = vec![(f32::INFINITY, f32::NEG_INFINITY); positions.len()];
    for t in triangles {
        for &v in t {
            let y0 = positions[v as usize].y;
            let r = &mut range[v as usize];
            for &w in t {
                let dy = positions[w as usize].y - y0;
                r.0 = r.0.min(dy);
                r.1 = r.1.max(dy);
            }
        }
    }
    range
        .into_iter()
        .map(|(lo, hi)| {
            let tol = 0.1 * (hi - lo);
            if lo > hi || hi - lo <= 0.0 {
                LipSide::Both
            } else if lo >= -tol {
                LipSide::Above
            } else if hi <= tol {
                LipSide::Below
            } else {
                LipSide::Both
            }
        })
        .collect()
}

/// The input vertices behind each of `count` surface vertices, as CSR lists
/// `(member_start, members)` (see [`SkinSurface::duplicates`]).
fn duplicate_lists(welded: &[u32], count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut member_start = vec![0u32; count + 1];
    for &w in welded {
        member_start[w as usize + 1] += 1;
    }
    for i in 0..count {
        member_start[i + 1] += member_start[i];
    }
    let mut fill = member_start.clone();
    let mut members = vec![0u32; welded.len()];
    for (i, &w) in welded.iter().enumerate() {
        members[fill[w as usize] as usize] = i as u32;
        fill[w as usize] += 1;
    }
    (member_start, members)
}

/// An axis-aligned box.
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

/// The box around the closed mouth's lip line: between the lip corners (8.3, 8.4) widened by
/// 0.1 MW0, ±0.35 MNS0 about the lip line, from half an MW0 behind the corners forward.
fn mouth_box(fps: &BTreeMap<FeaturePointId, Vec3>, fapu: &Fapu) -> Option<Box3> {
    let get = |id: FeaturePointId| fps.get(&id).copied();
    let (l, r) = (get(FeaturePointId::FP_8_3)?, get(FeaturePointId::FP_8_4)?);
    let mw = fapu.distances.mw0 as f32;
    let mns = fapu.distances.mns0 as f32;
    let lip_y = match (get(FeaturePointId::FP_2_2), get(FeaturePointId::FP_2_3)) {
        (Some(a), Some(b)) => (a.y + b.y) / 2.0,
        _ => (l.y + r.y) / 2.0,
    };
    let z = l.z.min(r.z);
    Some(Box3 {
        lo: Vec3::new(l.x.min(r.x) - 0.1 * mw, lip_y - 0.35 * mns, z - 0.5 * mw),
        hi: Vec3::new(l.x.max(r.x) + 0.1 * mw, lip_y + 0.35 * mns, f32::INFINITY),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Vertex 0 with a triangle above it, vertex 3 in the same place with a triangle below.
    fn lips() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let positions = vec![
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::ZERO,
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
        ];
        (positions, vec![[0, 1, 2], [3, 4, 5]])
    }

    #[test]
    fn opposite_sides_stay_apart_in_one_mesh_and_weld_across_meshes() {
        let (positions, triangles) = lips();
        let mouth = Some(Box3 {
            lo: Vec3::splat(-0.5),
            hi: Vec3::splat(0.5),
        });
        // One mesh: the closed slit's lips.
        let at = |m: Vec3| mouth.map(|b| (b, Some((m, 0.1))));
        let (welded, surface) =
            weld_outside_mouth(&positions, &triangles, &[0], 1e-6, at(Vec3::ZERO));
        assert_ne!(welded[0], welded[3]);
        assert_eq!(surface.len(), 6);
        // Without the lip line's middle too.
        let (welded, _) =
            weld_outside_mouth(&positions, &triangles, &[0], 1e-6, mouth.map(|b| (b, None)));
        assert_ne!(welded[0], welded[3]);
        // The same fans away from the lip line's middle: a seam (a lip on its socket).
        let (welded, surface) = weld_outside_mouth(
            &positions,
            &triangles,
            &[0],
            1e-6,
            at(Vec3::new(0.0, 0.3, -0.3)),
        );
        assert_eq!(welded[0], welded[3]);
        assert_eq!(surface.len(), 5);
        // Two meshes meeting there (a lip ending on a mouth socket primitive): one vertex.
        let (welded, surface) =
            weld_outside_mouth(&positions, &triangles, &[0, 3], 1e-6, at(Vec3::ZERO));
        assert_eq!(welded[0], welded[3]);
        assert_eq!(surface.len(), 5);
        // Outside the mouth box duplicates weld anyway.
        let (welded, _) = weld_outside_mouth(&positions, &triangles, &[0], 1e-6, None);
        assert_eq!(welded[0], welded[3]);
    }
}
