//! Apple ARKit's 52 blend shapes: canonical names, and which shapes of a rig play each.
//!
//! [`ARKIT_SHAPES`] lists them as Apple spells them (`ARFaceAnchor.BlendShapeLocation`, e.g.
//! `eyeBlinkLeft`, `jawOpen`), in the order iPhone capture apps (Live Link Face) write their
//! CSV columns. [`capture_name`] gives the capitalised column spelling (`EyeBlinkLeft`).
//!
//! A rig realises an ARKit shape by the shape of the same name after
//! [`normalise_shape_name`] (`eyeBlink_L` for `eyeBlinkLeft`), or, for the two shapes ARKit
//! has once but many rigs split per side (`browInnerUp`, `cheekPuff`), by the pair of
//! `…Left` / `…Right` halves played together (ICT-FaceKit's `browInnerUp_L` + `_R`).

use super::fap_map::{normalise_shape_name, ShapeLookup};
use super::Rig;

/// The 52 ARKit blend shapes, Apple's spelling, in capture-CSV order.
pub const ARKIT_SHAPES: [&str; 52] = [
    "eyeBlinkLeft",
    "eyeLookDownLeft",
    "eyeLookInLeft",
    "eyeLookOutLeft",
    "eyeLookUpLeft",
    "eyeSquintLeft",
    "eyeWideLeft",
    "eyeBlinkRight",
    "eyeLookDownRight",
    "eyeLookInRight",
    "eyeLookOutRight",
    "eyeLookUpRight",
    "eyeSquintRight",
    "eyeWideRight",
    "jawForward",
    "jawRight",
    "jawLeft",
    "jawOpen",
    "mouthClose",
    "mouthFunnel",
    "mouthPucker",
    "mouthRight",
    "mouthLeft",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthFrownLeft",
    "mouthFrownRight",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "mouthRollLower",
    "mouthRollUpper",
    "mouthShrugLower",
    "mouthShrugUpper",
    "mouthPressLeft",
    "mouthPressRight",
    "mouthLowerDownLeft",
    "mouthLowerDownRight",
    "mouthUpperUpLeft",
    "mouthUpperUpRight",
    "browDownLeft",
    "browDownRight",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "cheekPuff",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "tongueOut",
];

/// The capture-CSV spelling of an ARKit name: first letter upper case (`EyeBlinkLeft`).
pub fn capture_name(name: &str) -> String {
    let mut c = name.chars();
    c.next()
        .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
        .unwrap_or_default()
}

/// The index in [`ARKIT_SHAPES`] of a name in any spelling (`EyeBlinkLeft`, `eyeBlink_L`,
/// `blendShape1.eyeBlinkLeft`); `None` for anything else (`HeadYaw`, `cheekRaiser_L`).
pub fn arkit_index(name: &str) -> Option<usize> {
    let n = normalise_shape_name(name);
    ARKIT_SHAPES
        .iter()
        .position(|a| normalise_shape_name(a) == n)
}

/// The rig shapes that play ARKit shape `index` (empty when the rig has none).
pub fn rig_shapes_for(lookup: &ShapeLookup, index: usize) -> Vec<usize> {
    let Some(name) = ARKIT_SHAPES.get(index) else {
        return Vec::new();
    };
    if let Some(s) = lookup.find(name) {
        return vec![s];
    }
    // Only the one-sided ARKit shapes (browInnerUp, cheekPuff, jawOpen, ...) can be split.
    if name.ends_with("Left") || name.ends_with("Right") {
        return Vec::new();
    }
    [format!("{name}Left"), format!("{name}Right")]
        .iter()
        .filter_map(|h| lookup.find(h))
        .collect()
}

/// For every ARKit shape (in [`ARKIT_SHAPES`] order), the rig shapes that play it.
pub fn bind_rig(rig: &Rig) -> Vec<Vec<usize>> {
    let lookup = ShapeLookup::new(rig);
    (0..ARKIT_SHAPES.len())
        .map(|i| rig_shapes_for(&lookup, i))
        .collect()
}

/// The ARKit shape (index) a rig shape name plays, whole or as a half: `eyeBlink_L` →
/// `eyeBlinkLeft`, `browInnerUp_L` → `browInnerUp`.
pub fn arkit_index_of_rig_shape(name: &str) -> Option<usize> {
    arkit_index(name).or_else(|| {
        let n = normalise_shape_name(name);
        let base = n.strip_suffix('l').or_else(|| n.strip_suffix('r'))?;
        ARKIT_SHAPES
            .iter()
            .position(|a| normalise_shape_name(a) == base)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_spellings_match() {
        let mut seen = std::collections::HashSet::new();
        for a in ARKIT_SHAPES {
            assert!(seen.insert(normalise_shape_name(a)), "{a}");
        }
        assert_eq!(capture_name("eyeBlinkLeft"), "EyeBlinkLeft");
        for spelling in ["EyeBlinkLeft", "eyeBlink_L", "eyeBlinkLeft", "EYEBLINKLEFT"] {
            assert_eq!(arkit_index(spelling), Some(0), "{spelling}");
        }
        assert_eq!(arkit_index("HeadYaw"), None);
        assert_eq!(arkit_index(""), None);
        assert_eq!(
            arkit_index_of_rig_shape("browInnerUp_L").map(|i| ARKIT_SHAPES[i]),
            Some("browInnerUp")
        );
        assert_eq!(
            arkit_index_of_rig_shape("mouthSmile_R").map(|i| ARKIT_SHAPES[i]),
            Some("mouthSmileRight")
        );
        assert_eq!(arkit_index_of_rig_shape("cheekRaiser_L"), None);
    }
}
