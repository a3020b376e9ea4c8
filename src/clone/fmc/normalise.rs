//! Steps 1 and 8 — FAPU regional normalisation and denormalisation.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::NormalisationMode;
use crate::clone::CloneSurface;
use crate::fdp::Fapu;
use crate::spec::{FapuKind, FeaturePointId};

/// The FAPU per axis (x, y, z) of each feature-point group's region, for motions. Chosen so
/// that every translation FAP's unit lies on the axis its feature point moves along (pinned by
/// a test over the whole FAP table), which is what makes cloned motion FAP-compliant.
pub(crate) fn motion_kinds(group: u8) -> [FapuKind; 3] {
    use FapuKind::*;
    match group {
        // Chin/jaw and inner lip (open_jaw/lip FAPs: MNS vertical and in depth; stretch and
        // shift_jaw: MW sideways) — the paper's lip example {MW, MNS, MNS}.
        2 => [Mw, Mns, Mns],
        // Eyes: eyelids close in IRISD vertically; eyeball thrust is ES in depth.
        3 => [Es, Irisd, Es],
        // Eyebrows: raise in ENS, squeeze in ES.
        4 => [Es, Ens, Ens],
        // Cheeks: puff in ES sideways, lift in ENS.
        5 => [Es, Ens, Es],
        // Tongue: shift and thrust in MW, raise in MNS.
        6 => [Mw, Mns, Mw],
        // Outer lip, like the inner lip.
        8 => [Mw, Mns, Mns],
        // Nose and ears: every FAP in ENS.
        9 | 10 => [Ens, Ens, Ens],
        // Neck, hair line and anything else: the face's own proportions.
        _ => [Es, Ens, Es],
    }
}

/// The FAPU per axis used to normalise *positions*: the motion table except IRISD, which is
/// about a seventh of ES on a human face and would stretch the eye region over the brows (the
/// alignment space must stay a flat, non-folded picture of the face). Motions keep IRISD.
pub(crate) fn position_kinds(group: u8) -> [FapuKind; 3] {
    motion_kinds(group).map(|k| {
        if k == FapuKind::Irisd {
            FapuKind::Ens
        } else {
            k
        }
    })
}

/// The neutral distances (model units, not divided by 1024) behind `kinds`.
pub(crate) fn factors(fapu: &Fapu, kinds: [FapuKind; 3]) -> DVec3 {
    let d = |k: FapuKind| fapu.distance(k).unwrap_or(1.0);
    DVec3::new(d(kinds[0]), d(kinds[1]), d(kinds[2]))
}

/// Face-wide factors placing the feature points themselves in anchored mode.
pub(crate) fn global_factors(fapu: &Fapu) -> DVec3 {
    factors(fapu, [FapuKind::Es, FapuKind::Ens, FapuKind::Es])
}

/// A face in the normalised facial space.
pub(crate) struct Normalised {
    /// Centre of the face C: the midpoint between the pupils (3.5, 3.6).
    #[allow(dead_code)] // read by tests
    pub centre: DVec3,
    /// The closest feature point of each vertex (its region).
    pub region: Vec<FeaturePointId>,
    /// Normalised vertex positions.
    pub positions: Vec<DVec3>,
    /// Normalised feature points (each is its own region).
    pub fps: BTreeMap<FeaturePointId, DVec3>,
    /// Motion normalisation factors N(FP) of each vertex.
    pub motion_factors: Vec<DVec3>,
}

/// Normalises a surface (the pupils 3.5 and 3.6 must be known).
pub(crate) fn normalise(surface: &CloneSurface, mode: NormalisationMode) -> Normalised {
    let fp_list: Vec<(FeaturePointId, DVec3)> = surface
        .fp_positions
        .iter()
        .map(|(&id, p)| (id, p.as_dvec3()))
        .collect();
    let pupil = |id: FeaturePointId| surface.fp(id).unwrap_or(Vec3::ZERO).as_dvec3();
    let centre = (pupil(FeaturePointId::FP_3_5) + pupil(FeaturePointId::FP_3_6)) * 0.5;
    // A feature-point vertex belongs to its own point even where points coincide.
    let mut own: BTreeMap<u32, FeaturePointId> = BTreeMap::new();
    for (&id, &v) in &surface.fp_vertices {
        own.entry(v).or_insert(id);
    }
    let global = global_factors(&surface.fapu);
    let place = |id: FeaturePointId, fp: DVec3, v: DVec3| -> DVec3 {
        let n = factors(&surface.fapu, position_kinds(id.group()));
        match mode {
            NormalisationMode::Paper => (v - centre) / n,
            NormalisationMode::Anchored => (fp - centre) / global + (v - fp) / n,
            NormalisationMode::Global => (v - centre) / global,
        }
    };
    let per_vertex: Vec<(FeaturePointId, DVec3)> = surface
        .positions
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let v = p.as_dvec3();
            let (id, fp) = match own.get(&(i as u32)) {
                Some(&id) => (id, surface.fp(id).map_or(v, Vec3::as_dvec3)),
                None => fp_list
                    .iter()
                    .min_by(|a, b| a.1.distance_squared(v).total_cmp(&b.1.distance_squared(v)))
                    .copied()
                    .unwrap_or((FeaturePointId::from_parts(11, 4), v)),
            };
            (id, place(id, fp, v))
        })
        .collect();
    let fps = fp_list
        .iter()
        .map(|&(id, p)| (id, place(id, p, p)))
        .collect();
    Normalised {
        centre,
        motion_factors: per_vertex
            .iter()
            .map(|(id, _)| factors(&surface.fapu, motion_kinds(id.group())))
            .collect(),
        region: per_vertex.iter().map(|x| x.0).collect(),
        positions: per_vertex.into_iter().map(|x| x.1).collect(),
        fps,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::FapId;

    #[test]
    fn every_translation_fap_has_its_unit_on_its_axis() {
        for fap in FapId::low_level() {
            let info = fap.info();
            let (Some(kind), Some(dir)) = (info.fapu, info.direction()) else {
                continue;
            };
            let axis = dir.abs().max_position();
            assert!(
                (dir.abs()[axis] - 1.0).abs() < 1e-6,
                "FAP {fap} moves along an axis"
            );
            for fp in info.feature_points {
                assert_eq!(
                    motion_kinds(fp.group())[axis],
                    kind,
                    "FAP {fap} ({}) on FP {fp}",
                    info.name
                );
            }
        }
    }

    #[test]
    fn normalisation_round_trips_motion() {
        let Some(face) = crate::clone::fixtures::candide(&[], 0, 512.0) else {
            return;
        };
        for mode in [
            NormalisationMode::Paper,
            NormalisationMode::Anchored,
            NormalisationMode::Global,
        ] {
            let n = normalise(&face.surface, mode);
            // Normalised position of a displaced vertex minus the neutral one is the motion
            // divided by N(FP); multiplying back gives the displacement again.
            let fapu = face.surface.fapu;
            for m in &face.motions {
                for &(v, d) in &m.offsets {
                    let id = n.region[v as usize];
                    let p = face.surface.positions[v as usize].as_dvec3();
                    let fp = face.surface.fp(id).unwrap().as_dvec3();
                    let np = factors(&fapu, position_kinds(id.group()));
                    let moved = match mode {
                        NormalisationMode::Paper => (p + d.as_dvec3() - n.centre) / np,
                        NormalisationMode::Anchored => {
                            (fp - n.centre) / global_factors(&fapu) + (p + d.as_dvec3() - fp) / np
                        }
                        NormalisationMode::Global => {
                            (p + d.as_dvec3() - n.centre) / global_factors(&fapu)
                        }
                    };
                    let np = if mode == NormalisationMode::Global {
                        global_factors(&fapu)
                    } else {
                        np
                    };
                    let back = (moved - n.positions[v as usize]) * np;
                    assert!((back - d.as_dvec3()).length() < 1e-9);
                    let nm = n.motion_factors[v as usize];
                    assert!(((d.as_dvec3() / nm) * nm - d.as_dvec3()).length() < 1e-12);
                }
            }
            // The pupils' midpoint is the origin.
            let c = (n.fps[&"3.5".parse().unwrap()] + n.fps[&"3.6".parse().unwrap()]) * 0.5;
            assert!(c.length() < 1e-9, "{mode:?} {c}");
        }
    }
}
