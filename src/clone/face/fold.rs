//! Handing the target back in its own layout (module docs of [`super`], step 9): a one-mesh
//! head was cloned through an internal view with its eyes and teeth cut into part meshes
//! ([`super::split`]); this folds the view's FAT back into the user's mesh. Entries on the
//! view's skin and part meshes go back to the original vertex numbers through the split's
//! index maps, and the motion of transforms created only for cut parts is baked into
//! per-vertex displacements of those vertices ([`crate::fat::bake`]) — so is that of a part
//! transform kept for a whole mesh (an iris) when it also turns pieces cut out of a mesh that
//! goes back elsewhere (a highlight cut from a primitive whose occlusion shell is skin) —, within 1 % of the part's
//! size at every FAP value the table covers. A cut mesh goes back under a transform above
//! every piece's (both eye whites of one primitive: not the left eye's transform, which an
//! iris mesh of its own keeps). The face returned has exactly the target's
//! meshes, vertices and polygons; its transforms are the target's plus those created for
//! whole part meshes that still hold one (never a head: step 7 creates none).

use std::collections::{BTreeSet, HashMap};

use glam::{Affine3A, DMat3, DVec3, Vec3};
use rayon::prelude::*;

use super::rigid::hierarchy_ancestors;
use super::split::{mesh_pieces, SplitView};
use super::{CloneReport, Part};
use crate::error::{Diagnostic, Result};
use crate::face::{FaceFrames, FaceModel};
use crate::fat::bake::{bake_motion, on_borders, part_size, BakeRequest, BakedMesh};
use crate::fat::eval::{Activation, FatEvaluator};
use crate::fat::morph::MorphTarget;
use crate::fat::{FaceDefMesh, FaceDefTable, Fat, TableKey};
use crate::mesh::geometry::{adjacency, triangulate};
use crate::mesh::VertexIndex;
use crate::spec::{Directionality, FeaturePointId};

/// Share of a part's size a baked motion may be off by.
pub(super) const BAKE_TOLERANCE: f32 = 0.01;

/// One mesh of the view and where its vertices are in the target.
struct ViewMesh<'a> {
    /// Index in the view face.
    index: usize,
    /// View vertex → target vertex.
    to_target: &'a [u32],
    /// The part it is, `None` for the skin left of a cut mesh.
    part: Option<Part>,
}

/// One cut mesh of the target: its index there and its view meshes.
struct CutMeshes<'a> {
    /// Index in the target.
    target: usize,
    /// Its name.
    name: &'a str,
    /// The view meshes holding its vertices (the rest first).
    meshes: Vec<ViewMesh<'a>>,
    /// How many view meshes hold each of its vertices (2 on a cut along the lip line).
    multiplicity: Vec<u8>,
    /// The view transform its vertices are expressed in, in the output (see [`home`]).
    home: Option<usize>,
    /// The band across the lip line of its pieces cut there (the gums), if any.
    band: Option<CutBand>,
}

/// The cloned view `cloned` folded back into `target`'s layout (module docs). `targets` are the
/// source's morph targets (the FAP values each table covers); `report` gets warnings and its
/// rigid-part figures corrected for the transforms that were baked.
pub(super) fn fold_into_target(
    cloned: &FaceModel,
    target: &FaceModel,
    view: &SplitView,
    targets: &[MorphTarget],
    report: &mut CloneReport,
) -> Result<FaceModel> {
    let part_names: BTreeSet<&str> = view.parts.iter().map(|p| p.mesh.as_str()).collect();
    let baked = baked_transforms(cloned, &part_names, &report.rigid.created_transforms);
    let mut cuts: Vec<CutMeshes> = Vec::new();
    for cut in &view.cuts {
        let (Some(target_mesh), Some(rest)) =
            (target.mesh_index(&cut.mesh), cloned.mesh_index(&cut.mesh))
        else {
            continue;
        };
        let mut meshes = vec![ViewMesh {
            index: rest,
            to_target: &cut.rest_vertices,
            part: cut.rest,
        }];
        for p in view
            .parts
            .iter()
            .filter(|p| p.from == cut.mesh && p.mesh != cut.mesh)
        {
            if let Some(index) = cloned.mesh_index(&p.mesh) {
                meshes.push(ViewMesh {
                    index,
                    to_target: &p.source_vertices,
                    part: Some(p.part),
                });
            }
        }
        let mut multiplicity = vec![0u8; target.meshes[target_mesh].mesh.positions.len()];
        for m in &meshes {
            for &v in m.to_target {
                if let Some(k) = multiplicity.get_mut(v as usize) {
                    *k = k.saturating_add(1);
                }
            }
        }
        // Only where the mouth step ran: a source with a mouth of its own lends its gums'
        // real stretch (`part_motion`).
        let band = (report.mouth_interior > 0)
            .then(|| CutBand::new(target, target_mesh, &multiplicity))
            .flatten();
        // A rest that is one part while other pieces are another part's (both eye whites in
        // one primitive, an iris mesh of its own keeping the left eye's transform): the mesh
        // goes back whole, so it cannot sit in that part's transform; its home is above it
        // and every piece is baked.
        let chains: Vec<Vec<usize>> = meshes
            .iter()
            .skip(1)
            .map(|m| hierarchy_ancestors(cloned, cloned.meshes[m.index].transform))
            .collect();
        let mut home_t = home(cloned, rest, &baked);
        let mut steps = 0;
        while let Some(t) = home_t.filter(|&t| chains.iter().any(|c| !c.contains(&t))) {
            steps += 1;
            if cut.rest.is_none() || steps > cloned.transforms.len() {
                break;
            }
            home_t = cloned.transforms[t].parent;
        }
        cuts.push(CutMeshes {
            target: target_mesh,
            name: &cut.mesh,
            meshes,
            multiplicity,
            home: home_t,
            band,
        });
    }
    let ranges = covered_ranges(targets);
    // The transform whose motion a view mesh's vertices are baked with, if any: one baked
    // away, or, for a part cut out of a mesh that goes back elsewhere (an iris highlight cut
    // from a primitive whose occlusion shell is skin, its eye's transform kept for an iris
    // mesh of its own), the part's transform, which no longer holds those vertices.
    let baked_by = |cut: &CutMeshes, m: &ViewMesh| -> Option<usize> {
        m.part?;
        let t = cloned.meshes[m.index].transform?;
        let gone = hierarchy_ancestors(cloned, Some(t))
            .iter()
            .any(|&a| baked.contains(&cloned.transforms[a].name));
        let away = cut.home != Some(t);
        (gone || away).then_some(t)
    };
    // Transforms whose motion such a part takes apart from its cut mesh's home: a table
    // moving one of them (or a baked one) is baked.
    let mut carried: BTreeSet<&str> = baked.iter().map(String::as_str).collect();
    for cut in &cuts {
        let home_chain = hierarchy_ancestors(cloned, cut.home);
        for m in &cut.meshes {
            if let Some(t) = baked_by(cut, m) {
                for a in hierarchy_ancestors(cloned, Some(t)) {
                    if !home_chain.contains(&a) {
                        carried.insert(&cloned.transforms[a].name);
                    }
                }
            }
        }
    }
    // Transforms baked into several cut meshes (VRoid's eye white, iris and highlight layers,
    // each a primitive holding both eyes): their rows in every mesh share one set of borders,
    // so the part reads back as one motion (each mesh's bisection alone ends elsewhere).
    let mut cut_count: HashMap<usize, usize> = HashMap::new();
    for cut in &cuts {
        let ts: BTreeSet<usize> = cut.meshes.iter().filter_map(|m| baked_by(cut, m)).collect();
        for t in ts {
            *cut_count.entry(t).or_default() += 1;
        }
    }
    let spread: BTreeSet<usize> = cut_count
        .into_iter()
        .filter(|&(_, n)| n > 1)
        .map(|(t, _)| t)
        .collect();
    // Tables fold independently (one core each); warnings and tables keep table order.
    let folded: Vec<Result<(Option<FaceDefTable>, Vec<Diagnostic>)>> = cloned
        .fat
        .tables
        .par_iter()
        .map(|table| {
            let mut warnings: Vec<Diagnostic> = Vec::new();
            let mut out = FaceDefTable::new(table.key);
            let mut merged = Vec::new();
            let mut motion: Option<TableMotion> = None;
            let moves_baked = table
                .transforms
                .iter()
                .any(|t| carried.contains(t.transform.as_str()));
            let range = ranges.get(&table.key).copied().unwrap_or((0.0, 0.0));
            // Per spread transform, the borders its meshes need together.
            let mut shared: HashMap<usize, Vec<f64>> = HashMap::new();
            if moves_baked && !spread.is_empty() {
                for cut in &cuts {
                    let own = cut_borders(cloned, table, cut);
                    for m in &cut.meshes {
                        let Some(t) = baked_by(cut, m).filter(|t| spread.contains(t)) else {
                            continue;
                        };
                        let motion = match &mut motion {
                            Some(x) => x,
                            None => motion.insert(TableMotion::new(cloned, table)?),
                        };
                        let (b, _) = bake_view_mesh(target, cut, m, motion, table.key, range, &own);
                        shared
                            .entry(t)
                            .or_default()
                            .extend(b.entry.interval_borders);
                    }
                }
            }
            // The table's entries not yet taken by a cut (cloned only once they are kept).
            let mut rest: Vec<&FaceDefMesh> = table.meshes.iter().collect();
            for cut in &cuts {
                let mut entries: Vec<FaceDefMesh> = Vec::new();
                rest.retain(|e| {
                    match cut
                        .meshes
                        .iter()
                        .find(|m| cloned.meshes[m.index].name == e.mesh)
                    {
                        Some(m) => {
                            entries.push(FaceDefMesh {
                                mesh: cut.name.to_string(),
                                coord_index: e
                                    .coord_index
                                    .iter()
                                    .map(|&v| m.to_target.get(v as usize).copied().unwrap_or(v))
                                    .collect(),
                                interval_borders: e.interval_borders.clone(),
                                displacements: e.displacements.clone(),
                            });
                            false
                        }
                        None => true,
                    }
                });
                if moves_baked {
                    let borders: Vec<f64> = entries
                        .iter()
                        .flat_map(|e| e.interval_borders.iter().copied())
                        .collect();
                    for m in &cut.meshes {
                        let Some(t) = baked_by(cut, m) else {
                            continue;
                        };
                        let motion = match &mut motion {
                            Some(x) => x,
                            None => motion.insert(TableMotion::new(cloned, table)?),
                        };
                        let mut borders = borders.clone();
                        borders.extend(shared.get(&t).into_iter().flatten());
                        let (b, size) =
                            bake_view_mesh(target, cut, m, motion, table.key, range, &borders);
                        let tolerance = BAKE_TOLERANCE * size;
                        if b.max_error > tolerance {
                            warnings.push(Diagnostic::warning(format!(
                                "{}: the baked motion of {} is off by {:.3} % of its size",
                                table.key,
                                cloned.meshes[m.index].name,
                                100.0 * b.max_error / size.max(f32::MIN_POSITIVE)
                            )));
                        }
                        // A part this table does not move adds no entry.
                        if b.entry.displacements.iter().any(|d| *d != Vec3::ZERO) {
                            entries.push(b.entry);
                        }
                    }
                }
                let entry = merge_entries(entries, &cut.multiplicity);
                merged.extend(match (entry, &cut.band) {
                    (Some(e), Some(band)) => Some(band.smooth(e)),
                    (e, _) => e,
                });
            }
            out.meshes = merged;
            out.meshes.extend(rest.into_iter().cloned());
            out.transforms = table
                .transforms
                .iter()
                .filter(|t| !baked.contains(&t.transform))
                .cloned()
                .collect();
            let keep = !out.meshes.is_empty() || !out.transforms.is_empty();
            Ok((keep.then_some(out), warnings))
        })
        .collect();
    let mut fat = Fat::default();
    for f in folded {
        let (table, mut warnings) = f?;
        report.warnings.append(&mut warnings);
        fat.tables.extend(table);
    }
    let homes: HashMap<&str, Option<usize>> = cuts.iter().map(|c| (c.name, c.home)).collect();
    let face = layout_face(cloned, target, &baked, &homes, fat);
    correct_report(report, &baked);
    Ok(face)
}

/// Half the width of the band across a lip-line cut, in MNS0 ([`CutBand`]). The blend
/// squeezes the lower jaw's drop into the band: alma's `viseme_12` drops ICT's lower gums
/// 0.5 MNS0, and over a band half 0.5 MNS0 wide the gums' triangles turned 52° (ICT's own
/// FAT: 3.3°); over 1 MNS0 they turn less than the inner lip corners do (under 42°). Wider
/// takes in more of the upper gums: CANDIDE → ict `open_jaw` moves the upper row 4.0 % of
/// the chin (2.5 % at 0.5; `teeth_follow` allows 5 %).
const CUT_BAND: f32 = 1.0;

/// The vertices of a target mesh's pieces cut along the lip line (ICT's gums, tongue and
/// mouth socket: one piece reaching into both jaws) that lie within [`CUT_BAND`] × MNS0 of
/// where they cross the lip line (the height between 2.2 and 2.3), and each one's share of
/// the lower jaw's motion. Each side of the cut takes its own jaw's motion (the upper still,
/// the lower with the jaw), so the cut was a step: its vertices took the mean of both sides,
/// and the band of triangles beside it creased and folded (CANDIDE → ict `open_jaw`: 151°).
/// In the band, every table's motion is instead a blend of the two sides' motions, each
/// side's extended over the band as the affine map that fits it best (a jaw's motion is
/// rigid): `U + σ (L − U)`. The lower jaw's share `σ` is a smooth function of where a
/// vertex is — its height across the band (1 at the band's foot, 0 at its top), faded into
/// the vertex's own side (1 below the lip line, 0 above) as its distance from the crossings
/// grows to the band's half width — so it meets each side's own motion at the band's rim
/// and close vertices move alike whatever joins them. A harmonic blend over the band's
/// edges (before) did not: where the band's rim ran along a wall (the upper wall at the back
/// of ICT's gums piece, 3 mm from still vertices at the same height) its values fell to the
/// still side's within a triangle (alma → ict `viseme_12`: 53° where ICT's own FAT turns
/// 3.4°).
struct CutBand {
    /// The mesh's vertices at rest (the frame of its FAT entries).
    local: Vec<Vec3>,
    /// The cut pieces' vertices outside the band below and above the lip line: each side's
    /// motion is fitted on them.
    sides: [Vec<u32>; 2],
    /// The band's vertices and their shares of the lower side's motion.
    band: Vec<(u32, f32)>,
}

impl CutBand {
    /// The band of target mesh `mesh` whose vertices on a cut have `multiplicity` 2;
    /// `None` when nothing was cut along the lip line.
    fn new(target: &FaceModel, mesh: usize, multiplicity: &[u8]) -> Option<CutBand> {
        let m = &target.meshes.get(mesh)?.mesh;
        let on_cut: Vec<u32> = (0..m.positions.len() as u32)
            .filter(|&v| multiplicity.get(v as usize).is_some_and(|&k| k > 1))
            .collect();
        if on_cut.is_empty() {
            return None;
        }
        let reach = CUT_BAND * target.fapu().ok()?.distances.mns0 as f32;
        let fp = |id| target.feature_points.position(id);
        let lip_y = (fp(FeaturePointId::FP_2_2)?.y + fp(FeaturePointId::FP_2_3)?.y) / 2.0;
        let world = target.mesh_world(&target.frames(), mesh);
        let (piece, count) = mesh_pieces(m, 1e-6 * part_size(&world).max(f32::MIN_POSITIVE));
        let mut cut_piece = vec![false; count];
        for &v in &on_cut {
            cut_piece[piece[v as usize]] = true;
        }
        // The band is measured from where the cut pieces' triangles cross the lip line, not
        // from the cut's vertices: which side a polygon goes to depends on how it is split (a
        // quad or its two triangles), so the same head as quads (an OBJ) and as triangles (a
        // glTF) was cut a polygon apart and got bands a vertex apart (ICT's gums: 13.8 % of
        // `open_jaw`'s peak). The triangles here are the same in both (a convex quad is split
        // as a fan, as exporters do).
        let (triangles, _) = triangulate(&m.positions, &m.polygons);
        let adj = adjacency(m.positions.len(), &triangles);
        let mut crossings: Vec<Vec3> = Vec::new();
        for (a, next) in adj.iter().enumerate() {
            if !cut_piece[piece[a]] {
                continue;
            }
            for &b in next.iter().filter(|&&b| b as usize > a) {
                let (ya, yb) = (world[a].y - lip_y, world[b as usize].y - lip_y);
                if (ya <= 0.0) != (yb <= 0.0) {
                    crossings.push(world[a].lerp(world[b as usize], ya / (ya - yb)));
                }
            }
        }
        let index = VertexIndex::new(&crossings);
        let smoothstep = |t: f32| {
            let t = t.clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        };
        let mut sides: [Vec<u32>; 2] = [Vec::new(), Vec::new()];
        let mut band: Vec<(u32, f32)> = Vec::new();
        for v in 0..m.positions.len() {
            if !cut_piece[piece[v]] {
                continue;
            }
            let p = world[v];
            let own = if p.y <= lip_y { 1.0 } else { 0.0 };
            match index.nearest_vertex(p).filter(|&(_, d)| d < reach) {
                Some((_, d)) => {
                    let across = smoothstep((lip_y + reach - p.y) / (2.0 * reach));
                    let near = 1.0 - smoothstep(d / reach);
                    band.push((v as u32, own + near * (across - own)));
                }
                None => sides[usize::from(own == 0.0)].push(v as u32),
            }
        }
        if band.is_empty() {
            return None;
        }
        Some(CutBand {
            local: m.positions.clone(),
            sides,
            band,
        })
    }

    /// `entry` (one table's entry on the cut mesh) with its rates in the band re-set.
    fn smooth(&self, entry: FaceDefMesh) -> FaceDefMesh {
        let n = entry.interval_count();
        if n == 0 {
            return entry;
        }
        // Each vertex's row in the entry (the last, if listed twice), `NONE` if unlisted: a
        // table over the mesh, not a hash map (one per table, tens of thousands of rows).
        const NONE: u32 = u32::MAX;
        let size = entry
            .coord_index
            .iter()
            .map(|&v| v as usize + 1)
            .chain(self.band.iter().map(|&(v, _)| v as usize + 1))
            .fold(self.local.len(), usize::max);
        let mut slot = vec![NONE; size];
        for (k, &v) in entry.coord_index.iter().enumerate() {
            slot[v as usize] = k as u32;
        }
        let rate = |v: u32, j: usize| match slot[v as usize] {
            NONE => Vec3::ZERO,
            k => entry.displacements[k as usize * n + j],
        };
        // Per interval, each side's motion as an affine map (lower, upper).
        let maps: Vec<[Option<AffineFit>; 2]> = (0..n)
            .map(|j| {
                self.sides.each_ref().map(|side| {
                    AffineFit::of(side.iter().map(|&v| (self.local[v as usize], rate(v, j))))
                })
            })
            .collect();
        // Rows (vertex, its rates' place in `rates`): the entry's, then vertices of the band
        // the entry did not list.
        let mut rows: Vec<(u32, usize)> = entry
            .coord_index
            .iter()
            .enumerate()
            .map(|(k, &v)| (v, k))
            .collect();
        let mut rates_of: Vec<Vec3> = entry.displacements[..rows.len() * n].to_vec();
        let mut at = slot.clone();
        let mut rates: Vec<Vec3> = Vec::with_capacity(n);
        for &(v, share) in &self.band {
            let p = self.local[v as usize];
            rates.clear();
            rates.extend(maps.iter().enumerate().map(|(j, [lower, upper])| {
                let side = |f: &Option<AffineFit>| f.as_ref().map_or(rate(v, j), |f| f.at(p));
                let (l, u) = (side(lower), side(upper));
                u + share * (l - u)
            }));
            if !rates.iter().all(|r| r.is_finite()) {
                continue;
            }
            match at[v as usize] {
                NONE => {
                    if rates.iter().any(|r| *r != Vec3::ZERO) {
                        at[v as usize] = rows.len() as u32;
                        rows.push((v, rates_of.len() / n));
                        rates_of.extend_from_slice(&rates);
                    }
                }
                r => {
                    let k = rows[r as usize].1;
                    rates_of[k * n..(k + 1) * n].copy_from_slice(&rates);
                }
            }
        }
        rows.sort_by_key(|r| r.0);
        FaceDefMesh {
            mesh: entry.mesh,
            interval_borders: entry.interval_borders,
            coord_index: rows.iter().map(|r| r.0).collect(),
            displacements: rows
                .iter()
                .flat_map(|&(_, k)| rates_of[k * n..(k + 1) * n].iter().copied())
                .collect(),
        }
    }
}

/// The affine map `p ↦ A (p − c) + b` fitting displacements at points best (least squares).
struct AffineFit {
    centre: DVec3,
    linear: DMat3,
    offset: DVec3,
}

impl AffineFit {
    /// The fit of `(point, displacement)` samples; `None` with fewer than four samples or
    /// points on a plane (the map across it is not determined).
    fn of(samples: impl Iterator<Item = (Vec3, Vec3)> + Clone) -> Option<AffineFit> {
        let (mut sum, mut count) = (DVec3::ZERO, 0usize);
        for (p, _) in samples.clone() {
            sum += p.as_dvec3();
            count += 1;
        }
        if count < 4 {
            return None;
        }
        let centre = sum / count as f64;
        // Normal equations of the centred points: (Σ q qᵀ) Aᵀ = Σ q dᵀ, b the mean of d.
        let (mut qq, mut qd, mut mean) = (DMat3::ZERO, DMat3::ZERO, DVec3::ZERO);
        for (p, d) in samples {
            let (q, d) = (p.as_dvec3() - centre, d.as_dvec3());
            qq += DMat3::from_cols(q * q.x, q * q.y, q * q.z);
            qd += DMat3::from_cols(d * q.x, d * q.y, d * q.z);
            mean += d;
        }
        let det = qq.determinant();
        let scale = qq.col(0).x + qq.col(1).y + qq.col(2).z;
        if det.is_nan() || det.abs() <= 1e-12 * scale.powi(3) {
            return None;
        }
        Some(AffineFit {
            centre,
            linear: qd * qq.inverse(),
            offset: mean / count as f64,
        })
    }

    fn at(&self, p: Vec3) -> Vec3 {
        (self.linear * (p.as_dvec3() - self.centre) + self.offset).as_vec3()
    }
}

/// The transform view mesh `mesh`'s vertices are expressed in once the baked transforms are
/// gone: its own, or its nearest ancestor not baked (the rest of a cut part mesh sat under a
/// created part transform).
fn home(cloned: &FaceModel, mesh: usize, baked: &BTreeSet<String>) -> Option<usize> {
    let mut at = cloned.meshes.get(mesh)?.transform;
    let mut steps = 0;
    while let Some(t) = at {
        if !baked.contains(&cloned.transforms[t].name) || steps > cloned.transforms.len() {
            return Some(t);
        }
        at = cloned.transforms[t].parent;
        steps += 1;
    }
    None
}

/// Created transforms that hold only cut part meshes: their motion becomes displacements.
fn baked_transforms(
    cloned: &FaceModel,
    part_names: &BTreeSet<&str>,
    created: &[String],
) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (t, tf) in cloned.transforms.iter().enumerate() {
        if !created.contains(&tf.name) {
            continue;
        }
        let held: Vec<&str> = cloned
            .meshes
            .iter()
            .filter(|m| hierarchy_ancestors(cloned, m.transform).contains(&t))
            .map(|m| m.name.as_str())
            .collect();
        if !held.is_empty() && held.iter().all(|n| part_names.contains(n)) {
            out.insert(tf.name.clone());
        }
    }
    out
}

/// Per key, the FAP values its morph targets cover (0 included; both signs for bidirectional
/// FAPs, which the source's borders may show on one side only).
fn covered_ranges(targets: &[MorphTarget]) -> HashMap<TableKey, (f64, f64)> {
    let mut out: HashMap<TableKey, (f64, f64)> = HashMap::new();
    for t in targets {
        let r = out.entry(t.key).or_insert((0.0, 0.0));
        r.0 = r.0.min(t.value);
        r.1 = r.1.max(t.value);
    }
    for (key, r) in &mut out {
        if let TableKey::LowLevel(f) = key {
            if f.info().directionality == Some(Directionality::Bidirectional) {
                let a = r.1.max(-r.0);
                *r = (-a, a);
            }
        }
    }
    out
}

/// The borders of `table`'s entries on the view meshes of `cut`.
fn cut_borders(cloned: &FaceModel, table: &FaceDefTable, cut: &CutMeshes) -> Vec<f64> {
    table
        .meshes
        .iter()
        .filter(|e| {
            cut.meshes
                .iter()
                .any(|m| cloned.meshes[m.index].name == e.mesh)
        })
        .flat_map(|e| e.interval_borders.iter().copied())
        .collect()
}

/// The motion of view mesh `m` of `cut` under `key` (its transforms' motion, in the cut
/// mesh's frame) baked over `range` on `borders` and those bisection adds, and the size of
/// its vertices at rest.
fn bake_view_mesh(
    target: &FaceModel,
    cut: &CutMeshes,
    m: &ViewMesh,
    motion: &mut TableMotion,
    key: TableKey,
    range: (f64, f64),
    borders: &[f64],
) -> (BakedMesh, f32) {
    let original = &target.meshes[cut.target].mesh.positions;
    let neutral: Vec<Vec3> = m
        .to_target
        .iter()
        .map(|&v| original.get(v as usize).copied().unwrap_or(Vec3::ZERO))
        .collect();
    let size = part_size(&neutral);
    let b = bake_motion(
        &BakeRequest {
            mesh: cut.name,
            vertices: m.to_target,
            neutral: &neutral,
            range,
            borders,
            tolerance: BAKE_TOLERANCE * size,
        },
        |p| motion.in_mesh_frame(cut.home, m.index, key, p),
    );
    (b, size)
}

/// The transform motion of one table on the cloned view.
struct TableMotion<'a> {
    face: &'a FaceModel,
    evaluator: FatEvaluator,
    neutral: FaceFrames,
}

impl<'a> TableMotion<'a> {
    fn new(face: &'a FaceModel, table: &FaceDefTable) -> Result<Self> {
        let only = Fat {
            tables: vec![FaceDefTable {
                key: table.key,
                meshes: Vec::new(),
                transforms: table.transforms.clone(),
            }],
        };
        let evaluator = FatEvaluator::new(&only, &[], &face.transform_names())?;
        Ok(TableMotion {
            face,
            evaluator,
            neutral: face.frames(),
        })
    }

    /// The map, in the frame of view transform `home` (the frame the target mesh's vertices
    /// are in; `None` the face frame), that takes a vertex of view mesh `part` at neutral to
    /// where the table at `p` puts it: `W_home(p)⁻¹ · W_part(p) · W_part(0)⁻¹ · W_home(0)`.
    fn in_mesh_frame(
        &mut self,
        home: Option<usize>,
        part: usize,
        key: TableKey,
        p: f64,
    ) -> Affine3A {
        let mut out = self.evaluator.output();
        self.evaluator
            .evaluate(&[Activation { key, value: p }], &mut out);
        let locals: Vec<Affine3A> = self
            .face
            .transforms
            .iter()
            .zip(&out.transforms)
            .map(|(t, d)| t.animated_matrix(d))
            .collect();
        let posed = self.face.frames_with(&locals);
        let frame = |f: &FaceFrames| home.map_or(Affine3A::IDENTITY, |t| f.transforms[t]);
        frame(&posed).inverse()
            * posed.meshes[part]
            * self.neutral.meshes[part].inverse()
            * frame(&self.neutral)
    }
}

/// One entry for the target mesh from the view's entries (already in target numbering): on
/// the union of their borders, each vertex's rates summed over the view meshes that moved it
/// and divided by the number of view meshes holding it (a vertex on a cut takes the mean of
/// both sides, a side without an entry counting as still).
fn merge_entries(mut entries: Vec<FaceDefMesh>, multiplicity: &[u8]) -> Option<FaceDefMesh> {
    let first = entries.first()?;
    let shared = entries.iter().any(|e| {
        e.coord_index
            .iter()
            .any(|&v| multiplicity.get(v as usize).is_some_and(|&k| k > 1))
    });
    if entries.len() == 1 && !shared {
        return entries.pop();
    }
    let mut borders: Vec<f64> = entries
        .iter()
        .flat_map(|e| e.interval_borders.iter().copied())
        .chain([0.0])
        .collect();
    borders.sort_by(f64::total_cmp);
    borders.dedup();
    let n = borders.len().saturating_sub(1);
    // Every (vertex, entry, slot), sorted by vertex, entries in order within a vertex (the
    // sums in the same order as before, without a map of per-vertex vectors).
    let fine: Vec<FaceDefMesh> = entries.iter().map(|e| on_borders(e, &borders)).collect();
    let mut rows: Vec<(u32, u32, u32)> = fine
        .iter()
        .enumerate()
        .flat_map(|(i, f)| {
            f.coord_index
                .iter()
                .enumerate()
                .map(move |(slot, &v)| (v, i as u32, slot as u32))
        })
        .collect();
    rows.sort_unstable();
    let mut coord_index = Vec::with_capacity(rows.len());
    let mut displacements = Vec::with_capacity(rows.len() * n);
    for run in rows.chunk_by(|a, b| a.0 == b.0) {
        let v = run[0].0;
        let at = displacements.len();
        displacements.resize(at + n, Vec3::ZERO);
        for &(_, i, slot) in run {
            let slot = slot as usize;
            let from = &fine[i as usize].displacements[slot * n..(slot + 1) * n];
            for (s, r) in displacements[at..].iter_mut().zip(from) {
                *s += *r;
            }
        }
        let k = f32::from(multiplicity.get(v as usize).copied().unwrap_or(1).max(1));
        for s in &mut displacements[at..] {
            *s /= k;
        }
        coord_index.push(v);
    }
    Some(FaceDefMesh {
        mesh: first.mesh.clone(),
        interval_borders: borders,
        coord_index,
        displacements,
    })
}

/// The target's meshes (vertices, polygons, attributes as the user gave them) under the
/// cloned view's transforms, minus the baked ones, with `fat`; a cut mesh under its home
/// (`homes`, by name).
fn layout_face(
    cloned: &FaceModel,
    target: &FaceModel,
    baked: &BTreeSet<String>,
    homes: &HashMap<&str, Option<usize>>,
    fat: Fat,
) -> FaceModel {
    let mut face = cloned.clone();
    let keep: Vec<usize> = (0..cloned.transforms.len())
        .filter(|&t| !baked.contains(&cloned.transforms[t].name))
        .collect();
    let new_index: HashMap<usize, usize> = keep.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    face.transforms = keep
        .iter()
        .map(|&t| {
            let mut tf = cloned.transforms[t].clone();
            tf.parent = tf.parent.and_then(|p| new_index.get(&p).copied());
            tf
        })
        .collect();
    face.meshes = target
        .meshes
        .iter()
        .map(|m| {
            let mut out = m.clone();
            if let Some(c) = cloned.mesh_index(&m.name) {
                let at = match homes.get(m.name.as_str()) {
                    Some(&h) => h,
                    None => home(cloned, c, baked),
                };
                out.transform = at.and_then(|t| new_index.get(&t).copied());
                if cloned.meshes[c].mesh.positions.len() == m.mesh.positions.len() {
                    // Same mesh (not cut): positions as the clone left them (a part moved
                    // under a new transform is re-expressed in its frame).
                    out.mesh.positions = cloned.meshes[c].mesh.positions.clone();
                }
            }
            out
        })
        .collect();
    face.feature_points = target.feature_points.clone();
    face.fat = fat;
    face
}

/// The report without the baked transforms (they are not in the face).
fn correct_report(report: &mut CloneReport, baked: &BTreeSet<String>) {
    if baked.is_empty() {
        return;
    }
    let rigid = &mut report.rigid;
    rigid.created_transforms.retain(|t| !baked.contains(t));
    rigid.part_transforms.retain(|_, t| !baked.contains(t));
    rigid.installed_centres.retain(|(t, _)| !baked.contains(t));
    rigid.baked_transforms = baked.iter().cloned().collect();
    report
        .warnings
        .retain(|w| !w.message.starts_with("created transforms "));
    if !rigid.created_transforms.is_empty() {
        report.warnings.push(Diagnostic::warning(format!(
            "created transforms {}",
            rigid.created_transforms.join(", ")
        )));
    }
}
