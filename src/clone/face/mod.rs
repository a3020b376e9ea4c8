//! Cloning a whole face: the source's FAT onto a target [`FaceModel`], skin by a surface method
//! ([`super::fmc`], [`super::rbf`] or [`super::fit`]) and rigid parts by transforms, after
//! Pandžić 2003.
//!
//! # Steps (report timings use these names)
//!
//! 1. **`parts`** — each face's meshes are sorted into rigid parts from the feature points they
//!    hold ([`identify_parts`]): eyes (3.5, 3.6: the pupils), upper teeth (9.8, 9.10), lower
//!    teeth (9.9, 9.11), tongue (6.x); then meshes *connected* to a part (sharing a vertex
//!    position, quantised at 1e-5 of the face's size) join it unless they hold skin feature
//!    points or belong to another part (Pandžić's "connected meshes"). Meshes holding any other
//!    feature point, and meshes connected to those, are the deformable skin. Whatever is left
//!    (hair, hats) is listed and stays rigid with the head. Before that, a target whose skin
//!    mesh also holds its eyes, teeth and gums as separate connected pieces (a one-mesh head
//!    like the bundled `ict`) has them cut into part meshes ([`split_embedded_parts`]):
//!    roughly spherical pieces around the pupils are eyeballs; pieces behind the lips within
//!    1.5 MNS0 of the lip line are upper or lower teeth by their side of the lip line, and a
//!    piece reaching well into both jaws (ICT's gums and tongue) is cut along it. The tongue
//!    is not told apart from the lower gums: it follows the jaw. Likewise a part mesh (or
//!    glTF primitive) holding the feature points of several parts — both pupils in one eyes
//!    mesh, the upper and lower teeth points in one teeth mesh — is cut into one part each:
//!    by connected pieces, a piece going to the part whose points it holds or lie nearest,
//!    polygon by polygon when one piece holds several parts' points. An eye's eyeball is the
//!    piece holding its pupil, or — when the pupil is on an iris or cornea cap — the largest
//!    ball-shaped piece behind it that the pupil lies on (an eye white of its own, holding
//!    no feature point: `eyeball.rs`). A mesh holding no
//!    feature point whose every piece lies on an eyeball (within 1.3 radii of its centre:
//!    the eye white, VRoid's iris and highlight layers) is cut the same way, each
//!    piece to the eye it lies on, so the layers turn with their eyeballs — unless a piece's
//!    rim rests on the lids (an eye occlusion shell, a lacrimal film, an eye blend): a mesh
//!    all of such pieces is skin even when it shares no vertex with the skin, as it is in a
//!    one-mesh head, so it moves with the lids, and a mesh holding both kinds is cut: its
//!    pieces on an eye go to that eye, those on the lids stay in the mesh as skin. In a
//!    one-mesh head the same holds for its pieces: one lying wholly on an eyeball goes to
//!    the eye when its rim is clear of the lids and is skin when it rests on them. Each eye
//!    turns about its eye white's centre (step 7). A mesh without feature points behind the lips whose rows lie on either side of
//!    the lip line is cut by rows, and gums joined to a tongue in a mesh of their own (open,
//!    running back along the jaws) along the line, as in a one-mesh head. Each eye then turns
//!    about its own centre and the lower row follows the jaw; step 9 folds them back.
//!    With `fit`, a target that is one mesh with the source's only skin mesh (the same
//!    vertex count and polygons, but for a few quads split along the other diagonal: another
//!    identity of a rig's model) is not cut: the source moves its eyes, teeth and gums through its skin FAT, and `fit` carries
//!    that vertex to vertex ([`super::fit`], "One topology") — eyeballs keep the source's
//!    motion (none under a lid FAP), the gums stretch as the source's do.
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
//!    (within 1e-6 of the face's size) so seams do not cut the surface — except, inside the
//!    mouth box (between the lip corners, ±0.35 MNS0 around the lip line), a closed mouth's
//!    upper and lower lip vertices, which coincide and must stay apart: there duplicates are
//!    welded unless one's polygons lie all above it and the other's all below, or they come
//!    from different meshes (a seam down the lips or a skin / mouth primitive border, such as
//!    ICT's lips on its mouth socket, is welded; the slit within one mesh is not). A target that is one
//!    mesh with the source (same vertex counts and polygons) is welded exactly as the source
//!    ([`build_skin_surface_like`]). Results on a welded vertex go back to every duplicate that
//!    is a corner of some polygon: a vertex in no polygon is invisible and never moves
//!    (CANDIDE-3 keeps such unused copies of its midline points).
//! 4. **`motions`** — every table of the source FAT becomes one morph target per non-zero
//!    interval border ([`fat_to_morph_targets`]); skin displacements are turned into the face
//!    frame with each mesh's world 3×3 (a welded vertex takes the mean of its duplicates).
//! 5. The surface method's own steps (`fmc:*`, `rbf:*` or `fit:*`). `fit` scales each FAP by
//!    the target / source FAPU ratio of its unit itself, so step 6's rescale is not needed.
//! 6. **`rescale`** (RBF only, [`CloneOptions::rbf_fapu_rescale`]) — the RBF method carries a
//!    motion through the Jacobian of its volume morph, not through FAPU ratios, so a FAP's
//!    feature point does not move by `value × FAPU × direction` on the target. With the
//!    option on (default), each motion of a low-level translation FAP is multiplied by one
//!    factor so its feature point's displacement has the length of the source's displacement
//!    × (target FAPU / source FAPU) of that FAP's unit. Off reproduces the paper.
//!    **`guard`** (every method): a low-level translation FAP whose cloned feature point
//!    moves less than 5 % of the FAPU-scaled source motion (or more than 4×), or whose
//!    rescale factor lies outside [min(1, r)/4, 4·max(1, r)] (r = target/source FAPU of its
//!    unit), has *failed* — a rescale dividing by almost nothing once gave factors of 4.5·10⁵.
//!    It is repaired by a direct transfer (nearest source vertex in the aligned frame, times
//!    r), else by moving its feature point alone (the source's displacement there times r,
//!    fading out before the nearest other feature point: a coarse target's lid point may share
//!    its vertex with an eye corner, or lie beyond the source's surface by a still vertex),
//!    and re-checked; if that fails too the FAP's table is dropped. Either way it is listed
//!    in [`CloneReport::failed_faps`] and warned about.
//!    **`smooth`** (every method, `smooth.rs`): a motion must not crease, fold or spike where
//!    its source does not. Target triangles whose normal turns more than 1.25× the source
//!    motion's largest turn ([`crate::clone::quality::max_normal_turn`], at least 1°) are
//!    rough; their corners and one ring around them are smoothed by damped Laplacian steps
//!    (the FAP's own feature point held) until none is rough, at most 40 rounds. Such defects
//!    come from cloning across styles: target vertices reading unrelated parts of the source
//!    (lips or lids at the slit's corners, a nearest-vertex repair). A smooth clone is not
//!    changed. With [`CloneOptions::smooth_shares`] (default on) the turns are checked at a
//!    quarter and a half of each lid FAP's (19–22) motion too (the FAT interpolates: a lid turning about its
//!    eyeball folds on the way, beyond a border check's reach), and under a lid FAP the middle
//!    of its lid's margin (from the lid point half way to each corner) is held with the
//!    point, so the lashes riding it follow the lid. Smoothed motions are listed in [`CloneReport::smoothed`]. It runs once more
//!    after `gain` and `lid_close`, whose changes can crease a motion again (bruno → ict's
//!    lip corner).
//!    **`gain`** (every method): each low-level translation FAP's feature point is brought to
//!    the FAPU-scaled source motion, turned by the alignment's rotation into the target's own
//!    axes, by a smooth gain and turn field around it (Wendland C² bump over half an ES0,
//!    gain 1/10–10, turn up to 45°; else the difference is added over the point's edge
//!    neighbourhood; [`CloneReport::fapu_gain`]): a registration that put the target's
//!    feature point off the source's peak (a stylised brow onto a real one) no longer leaves
//!    the FAP half as strong. Not with FAPU scaling off
//!    ([`CloneOptions::rbf_fapu_rescale`] for RBF, `fapu_scale` for fit).
//!    **`lid_close`** (every method, with [`CloneOptions::lid_close`], default on;
//!    `lid_close.rs`), after `gain`: where the source's blink
//!    closes its eye (its lid points meet under both lid FAPs at one value, in both tables'
//!    first interval), the target's lid margins are moved vertically so that at that value
//!    the slit's gap along the corner line is the source's (in IRISD0), the top FAP taking
//!    the upper margin's share and the bottom FAP the lower's; each change fades into its lid
//!    within 0.2 ES0, fades out over the margin's middle (none at the lid point, which moves
//!    as its FAP defines), and is capped so that at the end of the first interval the slit
//!    is no more closed than the source's there; no vertex is taken further along the
//!    closing than its lid point (ICT's eye blend went 15 % past it). Across styles the surface method left the
//!    margin's drop a plateau with a steep fall at the corners (alma → ict: 0.10 IRISD0
//!    open, −0.18 crossed).
//!    **`lid_seam`** (with [`CloneOptions::lid_close`]; `lid_seam.rs`), after `lid_close`:
//!    at the source's closing value the line where the target's lids meet is smoothed
//!    along the slit (least squares against its second differences, corners and lid points
//!    held; the source's own detail put back, so a self-clone is kept) and the gap made the
//!    source's but at the lid points, changed through each lid's FAP and spread into the lid
//!    as `lid_close` does: `smooth`'s held margin middle had left a step where it ended
//!    (alma → ict: the closed line's roughness 0.17 IRISD0, ICT's own 0.08).
//!    **`eyeball`** (with [`CloneOptions::lid_close`]; `lid_eyeball.rs`): the FAT moves a
//!    vertex on a straight chord between borders, and a source lid turning about its eyeball
//!    crossed the target's eyeball on the way (alma → ict 0.21 radii deep, ICT's own FAT
//!    0.11). Skin near each eyeball part whose chord to a border passes inside the eye
//!    white's sphere (+2 %; or its own rest distance, if closer) deeper than the source's
//!    own chords dip into its eyeball under that motion (in radii; a self-clone is kept
//!    exactly) is pushed out along the eyeball's normal, the push spread smoothly over half
//!    a radius; before `smooth`'s second pass and `bound`.
//!    **`lid_cover`** (with [`CloneOptions::lid_cover`], default `Auto`; `lid_cover.rs`), after
//!    `eyeball` and `smooth`'s second pass (which took a single margin vertex's closing
//!    back, reopening the slit over the eye): at the source's closing value, where the
//!    target's margins are still apart over its eyeball part, they close to 0.02 IRISD0 of
//!    overlap (each by its FAP's share, spread into the lid as `lid_close` does); then there
//!    and at the end of the lid tables' first interval, lid vertices (resting in front of
//!    the eye) that the eyeball shows through from the front (its triangles' largest z over
//!    the vertex lies in front of it) need to come to 0.02 eye-white radii in front of it:
//!    each lid comes forward by the largest of those needs spread by a Wendland bump over
//!    half a radius, straight forward (no height change), through its lid's FAP at its
//!    first border. A target whose closed lids cover its eye is not changed.
//!    Alma's blink on ICT's head: eye vertices seen through the closed lids 69 / 70 per eye
//!    → 0 (ICT's own blink 0). By default (`Auto`) only on an eye where what the clone's
//!    closed lids leave of it differs from what the source's own leave of the source's: a
//!    share of the open eye more than 0.1 over the source's, or a sliver standing out less
//!    than half as far in front of the lids (alma → ICT 20 % at 0.033 half widths against
//!    alma's own 58 % at 0.137): a self-clone, and a cartoon whose own blink leaves its eye
//!    showing onto another (alma ↔ bruno), are kept.
//!    **`mouth`** (every method, `mouth_fill.rs`): the target's hidden mouth interior
//!    (skin behind the lips' front and hidden from the front, reached from the inner lip
//!    contour) takes a harmonic extension (edges weighed by inverse length) of the lips'
//!    motion that fades into the chin's small rigid motion below the lip line and into
//!    stillness above it, not the surface method's per-vertex motion, which read unrelated
//!    source places there. A face without such an interior is not changed, nor is any
//!    target of a source with a mouth interior of its own (a rig head hands on its motion).
//!    **`bound`** (every method, `turn_bound.rs`), last: a motion whose target still has a
//!    triangle turning more than 1.4× the source's largest turn (at least 1°; issue 21 asks
//!    1.5×) is re-solved around those triangles — a harmonic fill (edges weighed by inverse
//!    length) over their corners and a ring that grows each round, and in triangles still
//!    above the bound, if a sliver, the corner opposite the longest edge following that edge (a sliver
//!    moves with its base) — feature points, the lips' and lids' margins held, the round turning least kept
//!    if it turns less than the clone's own. Before the rounds, a FAP's own feature point
//!    whose triangles turn over the bound pulls its surroundings (the slit too, both lips
//!    alike) towards its motion by a bump along the mesh, the radius turning least kept:
//!    a coarse target's lip corner sampled at the peak of a dense source's motion no longer
//!    overtakes its neighbours (ict → bruno 172° → under 142°). It settles what `smooth`'s uniform steps cannot:
//!    CANDIDE-3's slivers at the sides of the head under the brow FAPs, ICT's tenth-of-a-
//!    millimetre triangles at the inner lip corners. Re-solved motions join
//!    [`CloneReport::smoothed`].
//! 7. **`rigid`** — transforms ([`RigidReport`]): the target's part transforms are the lowest
//!    transforms enclosing each part's meshes; the head's encloses all face meshes. A part
//!    sharing its lowest transform with other meshes (a tongue under the jaw with the lower
//!    teeth is fine for the teeth, not for the tongue) gets a new transform, child of that one
//!    (a root without one). No head transform is ever created: a root wrapped around the
//!    user's face would change their asset and turn the neck's base with the skull, so a
//!    source's head turns onto a face without one are re-made in step 10. Centres: eyes at their eyeball centre
//!    (least-squares sphere fit of the eye's largest piece, the eye white, not the caps in
//!    front of it; bounding-box centre if that piece is no sphere), head at 7.1;
//!    a transform the source rotates that has no centre (zero) gets the source's centre mapped
//!    through the alignment. Centres change with `translation` compensated, so the neutral
//!    pose does not move. Source `FaceDefTransform`s then map by role: rotations copy their
//!    axis (turned into the target's frame) and angle (AU is face independent); translations
//!    scale by target/source FAPU of the FAP's unit (high-level tables: ES for eyes, MNS for
//!    teeth and tongue, ENS for the head). When the target has a tongue or eyeball mesh of
//!    its own, source tables that deform that part (tongue roll, pupil dilation) bend it
//!    the same way (`part_deform`: vertex to vertex on one mesh, else nearest vertex of the
//!    two parts normalised to their bounding boxes; times the FAPU ratio). Otherwise, source
//!    tables that deform the tongue mesh
//!    (no surface method applies to it) become a rigid translation of the target's tongue
//!    transform by the FAPU-scaled displacement of the FAP's tongue feature point (the mean
//!    tongue displacement for high-level tables), as Pandžić does; tables whose tongue
//!    motion has no rigid equivalent (tongue roll) and deformations of other non-skin meshes
//!    (pupil dilation) are dropped with a warning. Parts cut out of a one-mesh target that
//!    the source has no part mesh for (a one-mesh source moves its teeth through the skin
//!    FAT) take, vertex by vertex, the source displacement where they lie on its inner
//!    pieces (closest point around the nearest inner vertex, barycentric; when the source has
//!    geometry there: median gap under 0.5 % of its size), times the FAPU ratio — not one
//!    rigid motion per part: a rig's gums and tongue stretch with the jaw (`part_motion`).
//!    Lower teeth and a tongue the source drives by neither a part nor such inner pieces —
//!    whole part meshes of the target (alma's teeth under their transform, cloned from ICT,
//!    whose teeth lie elsewhere), or any target of a source without teeth (CANDIDE-3) —
//!    take the small rigid motion fitted to the target's own cloned chin region, anchored
//!    at the chin point, under the jaw FAPs and the high-level tables (`jaw_follow`: the
//!    tongue rests on the mouth floor, so the jaw carries it). Upper teeth and eyeballs
//!    never take it.
//! 8. **`fat`** — per target skin mesh the face-frame displacements go back to the mesh frame
//!    (inverse world 3×3) and [`fat_from_morph_targets`] rebuilds the tables (multi-interval
//!    tables keep their borders); transform entries are appended. Small meshes of neither
//!    skin nor a part that lie on the skin (lashes, brow cards) ride on it (`attached`).
//!    Rows of lashes — their own mesh or pieces of a one-mesh head's skin — ride on their own
//!    lid's margin instead (`lid_margin`: the edge path corner → lid point → corner), never
//!    entering the eyeball. Every output number must be finite, or the clone fails.
//! 9. **`fold`** — a one-mesh target cut in step 1 comes back in its own layout: the cut is an
//!    internal view only. Entries on the view's skin and part meshes go back to the target
//!    mesh's own vertex numbers through the cut's index maps (a vertex on the cut along the
//!    lip line, in both jaws, takes the mean of both, and — when the `mouth` step ran —
//!    within ½ MNS0 of where the cut pieces cross the lip line every table's motion is the
//!    harmonic blend of both sides': no step), and transforms created in step 7 for
//!    cut parts alone are baked into per-vertex displacements of those vertices
//!    ([`crate::fat::bake`]: piecewise linear over the table's intervals, borders added until
//!    within 1 % of the part's size at every FAP value the source's table covers, both signs
//!    for bidirectional FAPs) and left out of the face. The output has exactly the target's
//!    meshes with every vertex, polygon and attribute in its order.
//! 10. **`turns`** — eyeball (23–26) and head (48–50) FAPs the source's FAT has no table for
//!     become the standard's rotations on the target ([`standard`]): about each eye white's
//!     centre and about 7.1 (derived where missing), on the target's eye and head transforms
//!     where it has them, else as per-vertex tables (the head's faded down the neck). A
//!     source's own eye and head turns given as vertex motion (a rig's) are re-made this way
//!     too, about the target's centres; given as transform rotations they map in step 7 —
//!     except head turns onto a target without a head transform, which are re-made here as
//!     per-vertex tables (their tables from step 8 give way). A source turn the target gets no
//!     table for (no pupils, no eye part) is named in a warning.
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
//!
//! # Where each step lives
//!
//! [`options`](CloneOptions) and [`report`](CloneReport) hold the settings and the report;
//! `parts` step 1 (`split` cuts one-mesh heads, `target_check` warns about damaged targets),
//! `align` step 2, `skin_surface` step 3 (welding), `motions` the moves between meshes and
//! the surface (steps 4 and 8), `rescale` step 6, the guard and the gain, `smooth` the smooth
//! step, `lid_close` the slits' closure, `lid_seam` the closed line, `lid_eyeball` the lids' clearance of the eyeballs,
//! `lid_cover` the closed lids in front of the eyes, `turn_bound` the bound, `rigid`, `part_motion` and `jaw_follow`
//! step 7, `assemble`, `attached` and `lid_margin` step 8 and `fold` step 9. This file runs them in order.
//!
//! [`fat_from_morph_targets`]: crate::fat::morph::fat_from_morph_targets

mod align;
mod assemble;
mod attached;
mod eyeball;
mod fold;
mod jaw_follow;
mod lid_close;
mod lid_cover;
mod lid_eyeball;
mod lid_margin;
mod lid_resting;
mod lid_seam;
mod motions;
mod mouth_fill;
mod options;
mod part_deform;
mod part_motion;
mod parts;
mod report;
mod rescale;
mod rigid;
mod skin_surface;
mod smooth;
mod split;
mod target_check;
mod turn_bound;
pub(crate) mod upright;

use std::collections::HashMap;
use std::time::Instant;

use rayon::prelude::*;

pub use align::Similarity;
pub use lid_resting::{lid_resting_layers, LidRestingLayer};
pub use options::{face_fmc_options, face_rbf_options, CloneOptions, LidCover, Method};
pub use parts::{identify_parts, FaceParts, Part};
pub use report::{CloneOutcome, CloneReport, LidCoverEye, RigidReport};
pub use rescale::{FapFailure, FapRepair};
pub use rigid::install_center;
pub use rigid::standard;
pub use skin_surface::{build_skin_surface, build_skin_surface_like, SkinSurface};
pub use split::{mesh_pieces, split_embedded_parts, SplitPart};

use super::fit::{clone_fit, clone_fit_prepared, SourcePrep};
use super::fmc::clone_fmc;
use super::rbf::clone_rbf;
use super::{CloneError, CloneSurface, SurfaceCloneResult, SurfaceMotion};
use crate::error::{Diagnostic, Result};
use crate::face::FaceModel;
use crate::fat::morph::{fat_to_morph_targets, MorphTarget};
use crate::fat::{Fat, TableKey};
use align::{alignment_rms, face_alignment};
use assemble::{assemble_fat, ClonedMotions, SourceMotions};
use motions::surface_motions;
use rescale::{gain_to_fapu, guard_motions, rescale_to_fapu};
use rigid::RigidPlan;
use smooth::{smooth_motions, SmoothTopology};

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
        Method::Fit => clone_fit(source, motions, target, &opts.fit),
    }
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
        return Err(CloneError::NoSourceFat {
            face: source.name.clone(),
        }
        .into());
    }
    // The source's eye and head turns, to say which the clone could not re-make.
    let source_turns: Vec<TableKey> = source
        .fat
        .tables
        .iter()
        .map(|t| t.key)
        .filter(|&k| standard::is_standard_rotation(k))
        .collect();
    // Eye and head turns a source moves as vertex motion (a rig's, the bundled `ict`'s) are
    // rotations by definition: the target gets them about its own centres (`standard`) rather
    // than through the skin's surface method, which cannot carry a rigid turn of its parts.
    let own_turns;
    let source = if source
        .fat
        .tables
        .iter()
        .any(|t| standard::is_standard_rotation(t.key) && t.transforms.is_empty())
    {
        let mut s = source.clone();
        s.fat
            .tables
            .retain(|t| !standard::is_standard_rotation(t.key) || !t.transforms.is_empty());
        own_turns = s;
        &own_turns
    } else {
        source
    };
    // 1. Parts (a one-mesh target first has its eyes, teeth and gums cut into part meshes).
    let clock = Instant::now();
    // The target's own FAT is replaced anyway; without it its skin mesh can be cut.
    let mut bare = target.clone();
    bare.fat = Fat::default();
    let sparts = identify_parts(source);
    // `fit` onto one mesh with the source's skin needs no cut (module docs, step 1).
    let whole = opts.method == Method::Fit
        && opts.fit.shared_topology
        && one_mesh_with(source, &sparts, &bare);
    // The cut is serial: the source's skin surface, and what `fit` reads of it alone, are
    // built beside it (errors reported in their own step, 3).
    let (view, (ssurf, fit_prep)) = rayon::join(
        || {
            if whole {
                None
            } else {
                split::split_view(&bare)
            }
        },
        || {
            let ssurf = build_skin_surface(source, &sparts.skin, &Similarity::IDENTITY);
            let prep = match (&ssurf, opts.method) {
                (Ok(s), Method::Fit) if !whole => SourcePrep::new(&s.surface, &opts.fit),
                _ => None,
            };
            (ssurf, prep)
        },
    );
    let (split_target, split) = match &view {
        Some(v) => (v.face.clone(), v.parts.clone()),
        None => (bare.clone(), Vec::new()),
    };
    let target = &split_target;
    let mut tparts = identify_parts(target);
    for s in &split {
        if let Some(mi) = target.mesh_index(&s.mesh) {
            tparts.skin.retain(|&m| m != mi);
            tparts.other.retain(|&m| m != mi);
            for list in tparts.parts.values_mut() {
                list.retain(|&m| m != mi);
            }
            tparts.parts.entry(s.part).or_default().push(mi);
        }
    }
    tparts.parts.retain(|_, l| !l.is_empty());
    report.split_parts = split;
    report.timings.push("parts", clock.elapsed().as_secs_f64());
    check_parts(&sparts, "source")?;
    warn_others(source, &sparts.other, "source", &mut report.warnings);
    // The target's others are named once step 8 knows which of them ride on the skin.
    check_parts(&tparts, "target")?;
    target_check::check_target(target, &tparts, &mut report.warnings);
    // 2. Alignment.
    let clock = Instant::now();
    let alignment = face_alignment(source, target, opts)?;
    report.alignment_rms = alignment_rms(source, target, &alignment);
    report.alignment = alignment;
    report.timings.push("align", clock.elapsed().as_secs_f64());
    // 3. Surfaces.
    let clock = Instant::now();
    let ssurf = ssurf?;
    let tsurf = build_skin_surface_like(target, &tparts.skin, &alignment, Some(&ssurf))?;
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
    // 5, 6. Surface method and FAPU rescale.
    let (mut cloned_motions, [tmargins, smargins]) = clone_skin_motions(
        (&ssurf, fit_prep),
        &tsurf,
        &motions,
        [(source, &sparts), (target, &tparts)],
        &alignment,
        opts,
        &mut report,
    )?;
    // Lashes ride on their own lid's margin: rows that are pieces of the skin take its
    // motion here, rows of their own mesh in step 8. A source with rows of lashes in its own
    // skin has them mapped onto the target's by the surface method, like for like (and a
    // target one mesh with the source keeps the source's lash motion vertex to vertex).
    let margins = tmargins;
    let source_rows = lid_margin::SkinRows::of(source, &ssurf, &smargins);
    if !whole && source_rows.is_empty() {
        lid_margin::SkinRows::of(target, &tsurf, &margins).carry(&mut cloned_motions);
    }
    let cloned: HashMap<(TableKey, u64), &SurfaceMotion> = cloned_motions
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
    // Part meshes the source deforms (its tongue) bend the target's part of that role; the
    // rigid step sees only what is left.
    let deformed = part_deform::part_deformations(
        &part_deform::PartSide {
            face: source,
            parts: &sparts,
            fapu: &ssurf.surface.fapu,
        },
        &targets,
        &part_deform::PartSide {
            face: &face,
            parts: &tparts,
            fapu: &tsurf.surface.fapu,
        },
        &alignment,
    );
    let rigid_targets: Vec<MorphTarget> = targets
        .iter()
        .map(|t| MorphTarget {
            meshes: t
                .meshes
                .iter()
                .filter(|m| !deformed.handled.contains(&m.mesh))
                .cloned()
                .collect(),
            ..t.clone()
        })
        .collect();
    let source_motions = SourceMotions {
        face: source,
        parts: &sparts,
        targets: &rigid_targets,
    };
    // Target parts the source has no part for: those cut out of a one-mesh target take the
    // source's motion where they lie on its inner pieces (a one-mesh source's teeth and
    // gums), vertex by vertex; the lower teeth and tongue left over (whole part meshes, a
    // source without teeth) follow the target's own cloned chin (`jaw_follow`).
    let undriven = part_motion::undriven_parts(&sparts, &tparts, &report.split_parts, &face);
    let todo: Vec<usize> = undriven.iter().filter(|u| u.cut).map(|u| u.mesh).collect();
    let (mut part_meshes, placed) =
        part_motion::part_motions(&todo, &face, &ssurf, &tsurf, &alignment, &motions);
    let on_jaw: Vec<usize> = undriven
        .iter()
        .filter(|u| matches!(u.part, Part::LowerTeeth | Part::Tongue) && !placed.contains(&u.mesh))
        .map(|u| u.mesh)
        .collect();
    for (key, meshes) in
        jaw_follow::jaw_motions(&face, &on_jaw, &tsurf, &alignment, &cloned_motions)
    {
        part_meshes.entry(key).or_default().extend(meshes);
    }
    for (key, meshes) in deformed.meshes {
        part_meshes.entry(key).or_default().extend(meshes);
    }
    // Small meshes on the skin (lashes as their own mesh or primitive) ride on it.
    let frames = face.frames();
    let riders = attached::attach_to_skin(&face, &frames, &tparts, &tsurf, &alignment, &margins);
    for m in &cloned_motions {
        let meshes = attached::attached_motion(&face, &frames, &riders, &tsurf, &alignment, m);
        if !meshes.is_empty() {
            part_meshes
                .entry((m.key, m.value.to_bits()))
                .or_default()
                .extend(meshes);
        }
    }
    report.attached_meshes = riders
        .iter()
        .map(|r| face.meshes[r.mesh].name.clone())
        .collect();
    let rigid_others: Vec<usize> = tparts
        .other
        .iter()
        .copied()
        .filter(|&m| !riders.iter().any(|r| r.mesh == m))
        .collect();
    warn_others(&face, &rigid_others, "target", &mut report.warnings);
    let cloned = ClonedMotions {
        skin: cloned,
        parts: part_meshes,
    };
    let fat = assemble_fat(
        &source_motions,
        &cloned,
        &face,
        &tsurf,
        &alignment,
        &rigid,
        &mut report,
    )?;
    let mut fat = fat;
    // Dropped FAPs lose their whole table (transform entries included): half a FAP is worse
    // than none.
    let dropped: Vec<&str> = report
        .failed_faps
        .iter()
        .filter(|f| !f.repaired)
        .map(|f| f.fap.as_str())
        .collect();
    fat.tables
        .retain(|t| !dropped.contains(&t.key.name().as_str()));
    face.fat = fat;
    report.timings.push("fat", clock.elapsed().as_secs_f64());
    // 9. The target's own layout.
    if let Some(v) = &view {
        let clock = Instant::now();
        face = fold::fold_into_target(&face, &bare, v, &targets, &mut report)?;
        report.timings.push("fold", clock.elapsed().as_secs_f64());
    }
    // A table left with nothing to move (pupil dilation onto eyes with no transform, tongue
    // FAPs onto a face without a tongue) has nothing to write, so a written clone would read
    // back without it.
    face.fat
        .tables
        .retain(|t| !t.meshes.is_empty() || !t.transforms.is_empty());
    // Eye and head turns the source does not give (module docs, step 10).
    let clock = Instant::now();
    // The target's cut from step 1 with its parts, unless `fit` took the whole mesh and
    // nothing was cut.
    let cut = (!whole).then_some(view.as_ref().map(|v| (v, &tparts)));
    if rigid.remakes_head_turns() {
        // The source turns its head transform and the target has none: what the head
        // tables hold now (the skin's share of the turn, if any) gives way to the whole turn.
        face.fat
            .tables
            .retain(|t| !matches!(t.key, TableKey::LowLevel(f) if (48..=50).contains(&f.number())));
    }
    report.standard_rotations = standard::add_standard_rotations_cut(&mut face, cut);
    warn_lost_turns(&source_turns, &face, &mut report);
    report.timings.push("turns", clock.elapsed().as_secs_f64());
    report.tables = face.fat.tables.len();
    report.source_parts = sparts;
    report.target_parts = tparts;
    Ok(CloneOutcome { face, report })
}

/// Warns about the source's eye and head turns (`source_turns`) that the clone `face` has no
/// table for, with the standard step's reasons (no pupils, no eye part).
fn warn_lost_turns(source_turns: &[TableKey], face: &FaceModel, report: &mut CloneReport) {
    let lost: Vec<String> = source_turns
        .iter()
        .filter(|&&k| face.fat.table(k).is_none())
        .map(|k| k.name())
        .collect();
    if lost.is_empty() {
        return;
    }
    let why = &report.standard_rotations.skipped;
    report.warnings.push(Diagnostic::warning(format!(
        "the source's turns {} are not cloned ({})",
        lost.join(", "),
        if why.is_empty() {
            "the target has no part for them".to_string()
        } else {
            why.join("; ")
        }
    )));
}

/// Steps 5 and 6: the surface method on the motions that move the skin, then (RBF) the FAPU
/// rescale, the guard, `smooth` and `gain` (which turns the wanted motions by the
/// `alignment`'s rotation). Returns one cloned motion per moving source motion, and the lid
/// margins of the target's and the source's skin (found while the surface method runs).
fn clone_skin_motions(
    (ssurf, fit_prep): (&SkinSurface, Option<SourcePrep>),
    tsurf: &SkinSurface,
    motions: &[SurfaceMotion],
    [(source, sparts), (target, tparts)]: [(&FaceModel, &FaceParts); 2],
    alignment: &Similarity,
    opts: &CloneOptions,
    report: &mut CloneReport,
) -> Result<(Vec<SurfaceMotion>, [lid_margin::LidMargins; 2])> {
    // Only motions that move the skin.
    let moving: Vec<SurfaceMotion> = motions
        .iter()
        .filter(|m| !m.offsets.is_empty())
        .cloned()
        .collect();
    // What `smooth`, `mouth`, `bound` and the lashes read of the neutral surfaces (lid
    // margins found once for all of them) is built while the surface method runs: its
    // sequential steps (`fit`'s factorisations) leave a core free.
    let (result, ((topology, margins), interior)) = rayon::join(
        || match (opts.method, fit_prep) {
            (Method::Fit, Some(prep)) => clone_fit_prepared(
                &ssurf.surface,
                &moving,
                &tsurf.surface,
                &opts.fit,
                Some(prep),
            ),
            _ => clone_surface(opts.method, &ssurf.surface, &moving, &tsurf.surface, opts),
        },
        || {
            rayon::join(
                || {
                    (
                        SmoothTopology::new(
                            &ssurf.surface,
                            &moving,
                            &tsurf.surface,
                            opts.smooth_shares,
                        ),
                        [&tsurf.surface, &ssurf.surface].map(lid_margin::LidMargins::of),
                    )
                },
                || {
                    // A source with a mouth interior of its own (a rig head) hands on its
                    // real motion there.
                    let own = mouth_fill::MouthInterior::new(ssurf).is_some();
                    (!own)
                        .then(|| mouth_fill::MouthInterior::new(tsurf))
                        .flatten()
                },
            )
        },
    );
    let mut result = result?;
    let topology = topology.with_lid_middles(&margins[0]);
    // The target's margins know its eyeballs (lashes and lids stay out of them).
    let [tm, sm] = margins;
    let margins = [
        tm.with_eyeballs(target, tparts, alignment),
        sm.with_eyeballs(source, sparts, &Similarity::IDENTITY),
    ];

    for (name, s) in &result.timings.steps {
        report
            .timings
            .push(&format!("{}:{name}", opts.method.name()), *s);
    }
    report.stats.extend(result.stats.clone());
    report.warnings.append(&mut result.warnings);
    // FAPU rescale (RBF only).
    if opts.method == Method::Rbf && opts.rbf_fapu_rescale {
        let clock = Instant::now();
        report.fapu_rescale =
            rescale_to_fapu(&ssurf.surface, &moving, &tsurf.surface, &mut result.motions);
        report
            .timings
            .push("rescale", clock.elapsed().as_secs_f64());
    }
    // The guard, for every method: no FAP leaves with a feature point that does not move or
    // a runaway factor.
    let clock = Instant::now();
    let rescaled = opts.method == Method::Rbf && opts.rbf_fapu_rescale;
    report.failed_faps = guard_motions(
        &ssurf.surface,
        &moving,
        &tsurf.surface,
        &mut result.motions,
        rescaled,
    );
    for f in &report.failed_faps {
        report.warnings.push(Diagnostic::warning(format!(
            "FAP {} at {}: {} (factor {:.4}); {}",
            f.fap,
            f.value,
            f.reason,
            f.factor,
            match f.repair {
                Some(FapRepair::DirectTransfer) => "repaired by a direct transfer",
                Some(FapRepair::FeaturePoint) => "repaired by moving its feature point",
                None => "its table is dropped",
            }
        )));
    }
    report.timings.push("guard", clock.elapsed().as_secs_f64());
    // No crease, fold or spike the source does not have; then each feature point moves by
    // its FAPU.
    let clock = Instant::now();
    report.smoothed = smooth_motions(
        &topology,
        &ssurf.surface,
        &moving,
        &tsurf.surface,
        opts.smooth_shares,
        &mut result.motions,
    );
    report.timings.push("smooth", clock.elapsed().as_secs_f64());
    // Not when FAPU scaling is turned off (the RBF paper's mode, fit without it).
    let scaled = match opts.method {
        Method::Rbf => opts.rbf_fapu_rescale,
        Method::Fit => opts.fit.fapu_scale,
        Method::Fmc => true,
    };
    if scaled {
        let clock = Instant::now();
        report.fapu_gain = gain_to_fapu(
            &ssurf.surface,
            &moving,
            &tsurf.surface,
            &mut result.motions,
            // FAP directions follow each face's own axes only while both are upright.
            if alignment.keeps_own_axes() {
                alignment.rotation
            } else {
                glam::DQuat::IDENTITY
            },
        );
        report.timings.push("gain", clock.elapsed().as_secs_f64());
    }
    // The slits close band by band where the source's does (the margins `smooth` held).
    let clock = Instant::now();
    if opts.lid_close {
        lid_close::close_lids(
            &ssurf.surface,
            &moving,
            &tsurf.surface,
            [&margins[0], &margins[1]],
            &mut result.motions,
        );
    }
    report
        .timings
        .push("lid_close", clock.elapsed().as_secs_f64());
    // Where the slits close, the lids meet along one smooth line.
    let clock = Instant::now();
    if opts.lid_close {
        lid_seam::seam_lids(
            &ssurf.surface,
            &moving,
            &tsurf.surface,
            [&margins[0], &margins[1]],
            &mut result.motions,
        );
    }
    report
        .timings
        .push("lid_seam", clock.elapsed().as_secs_f64());
    // No lid through an eyeball on its way to any border; before `smooth2` and `bound`,
    // which settle what the push turns.
    let clock = Instant::now();
    if opts.lid_close {
        lid_eyeball::keep_lids_out(
            &tsurf.surface,
            &margins[0],
            (&ssurf.surface, &margins[1], &moving),
            &mut result.motions,
        );
    }
    report
        .timings
        .push("eyeball", clock.elapsed().as_secs_f64());
    // The gain's bump changes the motion after `smooth` looked at it (bruno → ict's lip
    // corner under `viseme_1` turned 12× the source's): the same rule once more. A smooth
    // motion is not changed. Not after the mouth fill: smoothing the uniform-Laplacian way
    // there undid it (alma → ict 6.9 → 15.5).
    let clock = Instant::now();
    for (k, n) in smooth_motions(
        &topology,
        &ssurf.surface,
        &moving,
        &tsurf.surface,
        opts.smooth_shares,
        &mut result.motions,
    ) {
        *report.smoothed.entry(k).or_default() += n;
    }
    report
        .timings
        .push("smooth2", clock.elapsed().as_secs_f64());

    // Where the slits close, the closed lids cover the eyeballs from the front: by default
    // only where they leave the eye seen differently from the source's own closed lids.
    let clock = Instant::now();
    if opts.lid_cover != LidCover::Off {
        let fronts = lid_cover::EyeFront::of(target, tparts, alignment);
        if !fronts.is_empty() {
            // The target's own front, as `gain` keeps FAP directions on the target's axes.
            let forward = if alignment.keeps_own_axes() {
                (alignment.rotation * glam::DVec3::Z).as_vec3()
            } else {
                glam::Vec3::Z
            };
            report.lid_cover = lid_cover::cover_lids(
                opts.lid_cover,
                forward,
                (source, sparts, ssurf),
                &moving,
                &tsurf.surface,
                [&margins[0], &margins[1]],
                &fronts,
                &mut result.motions,
            );
        }
    }
    report
        .timings
        .push("lid_cover", clock.elapsed().as_secs_f64());
    // The hidden mouth interior: a smooth extension of the lips into the jaw's motion.
    let clock = Instant::now();
    if let Some(interior) = interior {
        report.mouth_interior = interior.vertices();
        result
            .motions
            .par_iter_mut()
            .for_each(|m| interior.fill(tsurf, m));
    }
    report.timings.push("mouth", clock.elapsed().as_secs_f64());
    // Last, an explicit bound on the skin's turn: what `smooth`'s uniform steps could not
    // settle (tiny or sliver triangles) is re-solved around it.
    let clock = Instant::now();
    let lids: Vec<u32> = margins[0].margin_vertices().collect();
    for (k, n) in turn_bound::bound_turns(
        &topology,
        &ssurf.surface,
        &moving,
        &tsurf.surface,
        &lids,
        &mut result.motions,
    ) {
        *report.smoothed.entry(k).or_default() += n;
    }
    report.timings.push("bound", clock.elapsed().as_secs_f64());
    Ok((result.motions, margins))
}

/// Whether `target` is one mesh with the source's only skin mesh: the same vertex count and
/// polygons ([`skin_surface::same_polygons`]: a rig head and another identity of its model,
/// or its reshaped copy).
fn one_mesh_with(source: &FaceModel, sparts: &FaceParts, target: &FaceModel) -> bool {
    let [s] = sparts.skin.as_slice() else {
        return false;
    };
    let [t] = target.meshes.as_slice() else {
        return false;
    };
    let s = &source.meshes[*s].mesh;
    s.positions.len() == t.mesh.positions.len()
        && skin_surface::same_polygons(&s.polygons, &t.mesh.polygons)
}

/// A face (`side` = "source" or "target") needs a skin mesh.
fn check_parts(parts: &FaceParts, side: &str) -> Result<()> {
    if parts.skin.is_empty() {
        return Err(CloneError::NoSkin {
            face: format!("{side} face"),
        }
        .into());
    }
    Ok(())
}

/// One warning naming the meshes (`others`) of neither skin nor a part: a source's are not
/// cloned, a target's get no FAT motion (a Ready Player Me body or outfit stays on its spine
/// joints, not on the head).
fn warn_others(face: &FaceModel, others: &[usize], side: &str, warnings: &mut Vec<Diagnostic>) {
    if others.is_empty() {
        return;
    }
    let names: Vec<&str> = others
        .iter()
        .map(|&m| face.meshes[m].name.as_str())
        .collect();
    let fate = if side == "source" {
        "their motion is not cloned"
    } else {
        "they get no FAT motion (they move only with their own nodes or joints)"
    };
    warnings.push(Diagnostic::warning(format!(
        "{side} meshes {} are neither skin nor a part; {fate}",
        names.join(", ")
    )));
}

#[cfg(test)]
mod tests;
