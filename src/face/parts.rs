//! Which part of a face each triangle shows — skin, eye white, iris, pupil, teeth, tongue,
//! mouth cavity, hair — so pictures can give each its own material.
//!
//! Meshes are classified by name (`eye`, `teeth`, `tongue`, `mouth`/`cavity`/`gum`,
//! `lash`/`brow`/`hair`; anything else is skin). Within a mesh, feature points refine it:
//!
//! - an **eye** mesh's triangles within [`IRIS_DEGREES`] of the direction from the
//!   eyeball's centre to its pupil point (3.5 left, 3.6 right, whichever is nearer) are
//!   iris, within [`PUPIL_DEGREES`] pupil;
//! - a **skin** mesh's triangles between the lip corners (8.3, 8.4), within the lip height
//!   (8.1 to 8.2) widened by a quarter of the mouth width, at most one mouth width behind
//!   the corners, and **hidden from the front** in the neutral face (a ray from the
//!   triangle's centre towards +z meets the skin again: the closed lips cover it) are the
//!   **mouth cavity** (a modelled mouth bag). A receding chin is in that box too, but seen
//!   from the front, so it stays skin. Skin without a bag (a mouth slit) shows the inside of
//!   the head through the lips: that is what [`FacePart::inside_colour`] paints.

use glam::Vec3;

use crate::fdp::FeaturePointSet;
use crate::spec::FeaturePointId;

/// Angle from the pupil direction within which an eyeball is iris (an iris of about 6 mm
/// on a 12 mm eyeball radius).
pub const IRIS_DEGREES: f32 = 30.0;
/// Angle within which it is pupil.
pub const PUPIL_DEGREES: f32 = 12.0;

/// A part of a face with its own look.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FacePart {
    /// Skin (also what is not recognised).
    Skin,
    /// The white of an eyeball.
    EyeWhite,
    /// The iris.
    Iris,
    /// The pupil.
    Pupil,
    /// Teeth.
    Teeth,
    /// The tongue.
    Tongue,
    /// The inside of the mouth (mouth bag, gums, throat).
    MouthCavity,
    /// Eyebrows, eyelashes, hair.
    Hair,
}

impl FacePart {
    /// The part a mesh of this name shows (eyes as [`FacePart::EyeWhite`]).
    pub fn of_mesh_name(name: &str) -> FacePart {
        let n = name.to_ascii_lowercase();
        let has = |words: &[&str]| words.iter().any(|w| n.contains(w));
        if has(&["lash", "brow", "hair", "beard"]) {
            FacePart::Hair
        } else if has(&["teeth", "tooth"]) {
            FacePart::Teeth
        } else if has(&["tongue"]) {
            FacePart::Tongue
        } else if has(&["mouth", "cavity", "gum", "throat", "socket"]) && !has(&["eye"]) {
            FacePart::MouthCavity
        } else if has(&["eyelid", "lid"]) {
            FacePart::Skin
        } else if has(&["eye", "iris", "pupil", "cornea", "sclera"]) {
            FacePart::EyeWhite
        } else {
            FacePart::Skin
        }
    }

    /// Display colour (sRGB) when the model gives none — or always, for the parts a model
    /// colour cannot describe (iris, pupil, mouth cavity are regions within a mesh).
    pub fn default_colour(self) -> [f32; 3] {
        match self {
            FacePart::Skin => [0.82, 0.66, 0.56],
            FacePart::EyeWhite => [0.93, 0.93, 0.90],
            FacePart::Iris => [0.28, 0.19, 0.12],
            FacePart::Pupil => [0.03, 0.03, 0.03],
            FacePart::Teeth => [0.94, 0.92, 0.84],
            FacePart::Tongue => [0.62, 0.22, 0.25],
            FacePart::MouthCavity => [0.42, 0.10, 0.12],
            FacePart::Hair => [0.20, 0.14, 0.10],
        }
    }

    /// Whether a model's own mesh colour applies to this part.
    pub fn takes_mesh_colour(self) -> bool {
        !matches!(
            self,
            FacePart::Iris | FacePart::Pupil | FacePart::MouthCavity
        )
    }

    /// Colour of this part's back faces (sRGB): the inside of the head seen through the
    /// mouth is mouth cavity; `None` keeps the front colour, darkened.
    pub fn inside_colour(self) -> Option<[f32; 3]> {
        match self {
            FacePart::Skin | FacePart::MouthCavity => Some(FacePart::MouthCavity.default_colour()),
            _ => None,
        }
    }
}

/// The triangles of one mesh grouped by part, in their original order within each group.
pub fn split_mesh(
    mesh_part: FacePart,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    feature_points: &FeaturePointSet,
) -> Vec<(FacePart, Vec<[u32; 3]>)> {
    let classify: Box<dyn Fn(Vec3) -> FacePart> = match mesh_part {
        FacePart::EyeWhite => match eye_frame(positions, feature_points) {
            Some((centre, front)) => {
                let iris = IRIS_DEGREES.to_radians().cos();
                let pupil = PUPIL_DEGREES.to_radians().cos();
                Box::new(move |c: Vec3| {
                    let cos = (c - centre).normalize_or_zero().dot(front);
                    if cos >= pupil {
                        FacePart::Pupil
                    } else if cos >= iris {
                        FacePart::Iris
                    } else {
                        FacePart::EyeWhite
                    }
                })
            }
            None => Box::new(|_| FacePart::EyeWhite),
        },
        FacePart::Skin => match MouthBox::of(feature_points) {
            Some(b) => {
                let blockers = b.blockers(positions, triangles);
                Box::new(move |c: Vec3| {
                    if b.contains(c) && hidden_from_front(c, &blockers) {
                        FacePart::MouthCavity
                    } else {
                        FacePart::Skin
                    }
                })
            }
            None => Box::new(|_| FacePart::Skin),
        },
        other => Box::new(move |_| other),
    };
    let mut groups: Vec<(FacePart, Vec<[u32; 3]>)> = Vec::new();
    for t in triangles {
        let Some(corners) = t
            .iter()
            .map(|&i| positions.get(i as usize).copied())
            .collect::<Option<Vec<Vec3>>>()
        else {
            continue;
        };
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let part = classify(centroid);
        match groups.iter_mut().find(|(p, _)| *p == part) {
            Some((_, g)) => g.push(*t),
            None => groups.push((part, vec![*t])),
        }
    }
    groups
}

/// Eyeball centre (vertex mean) and unit direction to its pupil feature point.
fn eye_frame(positions: &[Vec3], fps: &FeaturePointSet) -> Option<(Vec3, Vec3)> {
    let finite: Vec<Vec3> = positions
        .iter()
        .copied()
        .filter(|p| p.is_finite())
        .collect();
    if finite.is_empty() {
        return None;
    }
    let centre = finite.iter().copied().sum::<Vec3>() / finite.len() as f32;
    let pupil = [(3, 5), (3, 6)]
        .into_iter()
        .filter_map(|(g, i)| FeaturePointId::new(g, i).and_then(|id| fps.position(id)))
        .min_by(|a, b| a.distance(centre).total_cmp(&b.distance(centre)))?;
    let front = (pupil - centre).try_normalize()?;
    Some((centre, front))
}

/// The region of a skin mesh that is a modelled mouth bag (see the module docs).
#[derive(Clone, Copy, Debug)]
struct MouthBox {
    min: Vec3,
    max: Vec3,
}

impl MouthBox {
    fn of(fps: &FeaturePointSet) -> Option<MouthBox> {
        let at = |g, i| FeaturePointId::new(g, i).and_then(|id| fps.position(id));
        let (top, bottom, left, right) = (at(8, 1)?, at(8, 2)?, at(8, 3)?, at(8, 4)?);
        let width = (left.x - right.x).abs();
        if !(width.is_finite() && width > 0.0) {
            return None;
        }
        let back = left.z.min(right.z);
        Some(MouthBox {
            min: Vec3::new(
                left.x.min(right.x),
                bottom.y.min(top.y) - 0.25 * width,
                back - width,
            ),
            max: Vec3::new(
                left.x.max(right.x),
                top.y.max(bottom.y) + 0.25 * width,
                top.z.max(bottom.z).max(back),
            ),
        })
    }

    fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The triangles that can hide a point of the box from the front: those overlapping
    /// its x/y extent, as corner triples.
    fn blockers(&self, positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<[Vec3; 3]> {
        triangles
            .iter()
            .filter_map(|t| {
                let c = [
                    *positions.get(t[0] as usize)?,
                    *positions.get(t[1] as usize)?,
                    *positions.get(t[2] as usize)?,
                ];
                let lo = c[0].min(c[1]).min(c[2]);
                let hi = c[0].max(c[1]).max(c[2]);
                let overlaps = lo.x <= self.max.x
                    && hi.x >= self.min.x
                    && lo.y <= self.max.y
                    && hi.y >= self.min.y
                    && hi.z > self.min.z;
                (overlaps && c.iter().all(|p| p.is_finite())).then_some(c)
            })
            .collect()
    }
}

/// Whether a ray from `p` towards +z passes through one of `blockers` in front of `p`.
fn hidden_from_front(p: Vec3, blockers: &[[Vec3; 3]]) -> bool {
    blockers.iter().any(|&[a, b, c]| {
        // Barycentric coordinates of p in the triangle's x/y projection.
        let d = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        if d.abs() <= f32::EPSILON {
            return false;
        }
        let u = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / d;
        let v = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / d;
        if u < 0.0 || v < 0.0 || u + v > 1.0 {
            return false;
        }
        let z = a.z + u * (b.z - a.z) + v * (c.z - a.z);
        // In front by more than a rounding error (the triangle holding p itself is not).
        z > p.z + 1e-4 * (1.0 + p.z.abs())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdp::FeaturePoint;

    #[test]
    fn mesh_names() {
        let f = FacePart::of_mesh_name;
        assert_eq!(f("eye_l"), FacePart::EyeWhite);
        assert_eq!(f("EyeBall_R"), FacePart::EyeWhite);
        assert_eq!(f("teeth_upper"), FacePart::Teeth);
        assert_eq!(f("tongue"), FacePart::Tongue);
        assert_eq!(f("mouthSocket"), FacePart::MouthCavity);
        assert_eq!(f("eyelashes"), FacePart::Hair);
        assert_eq!(f("eyelid_l"), FacePart::Skin);
        assert_eq!(f("skin"), FacePart::Skin);
        assert_eq!(f("candide"), FacePart::Skin);
    }

    #[test]
    fn eyes_get_an_iris_around_the_pupil_point() {
        let face = crate::synth::alma().to_face_model();
        let neutral = face.neutral_world_positions();
        let eye = face.meshes.iter().position(|m| m.name == "eye_l").unwrap();
        let tris = face.meshes[eye].mesh.triangles();
        let groups = split_mesh(
            FacePart::EyeWhite,
            &neutral[eye],
            &tris,
            &face.feature_points,
        );
        let count = |p: FacePart| {
            groups
                .iter()
                .find(|(q, _)| *q == p)
                .map_or(0, |(_, t)| t.len())
        };
        assert!(count(FacePart::Pupil) > 0);
        assert!(count(FacePart::Iris) > 0);
        assert!(count(FacePart::EyeWhite) > count(FacePart::Iris));
        assert_eq!(
            count(FacePart::Pupil) + count(FacePart::Iris) + count(FacePart::EyeWhite),
            tris.len()
        );
    }

    #[test]
    fn a_mouth_bag_behind_the_lips_is_cavity() {
        let mut fps = FeaturePointSet::new();
        let fp = |g, i, p: Vec3| FeaturePoint::at(FeaturePointId::new(g, i).unwrap(), p);
        fps.insert(fp(8, 1, Vec3::new(0.0, 5.0, 10.0)));
        fps.insert(fp(8, 2, Vec3::new(0.0, -5.0, 10.0)));
        fps.insert(fp(8, 3, Vec3::new(25.0, 0.0, 5.0)));
        fps.insert(fp(8, 4, Vec3::new(-25.0, 0.0, 5.0)));
        // A triangle in the bag, the lips covering it, the back of the head, and a receding
        // chin below the lips: behind the corners but seen from the front.
        let p = vec![
            Vec3::new(-5.0, 0.0, -10.0),
            Vec3::new(5.0, 0.0, -10.0),
            Vec3::new(0.0, 5.0, -10.0),
            Vec3::new(-20.0, -8.0, 10.0),
            Vec3::new(20.0, -8.0, 10.0),
            Vec3::new(0.0, 10.0, 10.0),
            Vec3::new(-5.0, 0.0, -90.0),
            Vec3::new(5.0, 0.0, -90.0),
            Vec3::new(0.0, 5.0, -90.0),
            Vec3::new(-5.0, -14.0, 0.0),
            Vec3::new(5.0, -14.0, 0.0),
            Vec3::new(0.0, -10.0, 0.0),
        ];
        let t = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]];
        let groups = split_mesh(FacePart::Skin, &p, &t, &fps);
        assert_eq!(
            groups,
            vec![
                (FacePart::MouthCavity, vec![[0, 1, 2]]),
                (FacePart::Skin, vec![[3, 4, 5], [6, 7, 8], [9, 10, 11]]),
            ]
        );
        // Without lip points everything stays skin.
        let plain = split_mesh(FacePart::Skin, &p, &t, &FeaturePointSet::new());
        assert_eq!(plain, vec![(FacePart::Skin, t)]);
    }
}
