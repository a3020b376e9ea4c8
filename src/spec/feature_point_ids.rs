// Named constants for every feature point of specs/feature-points.csv; `tests::named_feature_point_constants_match_the_table` pins them.

use super::FeaturePointId;

/// Every feature point the standard defines, by label: `FeaturePointId::FP_7_1` is 7.1.
impl FeaturePointId {
    /// 2.1: Bottom of the chin.
    pub const FP_2_1: FeaturePointId = FeaturePointId::from_parts(2, 1);
    /// 2.2: Middle of the inner upper lip contour.
    pub const FP_2_2: FeaturePointId = FeaturePointId::from_parts(2, 2);
    /// 2.3: Middle of the inner lower lip contour.
    pub const FP_2_3: FeaturePointId = FeaturePointId::from_parts(2, 3);
    /// 2.4: Left corner of the inner lip contour.
    pub const FP_2_4: FeaturePointId = FeaturePointId::from_parts(2, 4);
    /// 2.5: Right corner of the inner lip contour.
    pub const FP_2_5: FeaturePointId = FeaturePointId::from_parts(2, 5);
    /// 2.6: Inner upper lip contour halfway between 2.2 and 2.4.
    pub const FP_2_6: FeaturePointId = FeaturePointId::from_parts(2, 6);
    /// 2.7: Inner upper lip contour halfway between 2.2 and 2.5.
    pub const FP_2_7: FeaturePointId = FeaturePointId::from_parts(2, 7);
    /// 2.8: Inner lower lip contour halfway between 2.3 and 2.4.
    pub const FP_2_8: FeaturePointId = FeaturePointId::from_parts(2, 8);
    /// 2.9: Inner lower lip contour halfway between 2.3 and 2.5.
    pub const FP_2_9: FeaturePointId = FeaturePointId::from_parts(2, 9);
    /// 2.10: Chin boss.
    pub const FP_2_10: FeaturePointId = FeaturePointId::from_parts(2, 10);
    /// 2.11: Left corner of the chin.
    pub const FP_2_11: FeaturePointId = FeaturePointId::from_parts(2, 11);
    /// 2.12: Right corner of the chin.
    pub const FP_2_12: FeaturePointId = FeaturePointId::from_parts(2, 12);
    /// 2.13: Left corner of the jaw bone.
    pub const FP_2_13: FeaturePointId = FeaturePointId::from_parts(2, 13);
    /// 2.14: Right corner of the jaw bone.
    pub const FP_2_14: FeaturePointId = FeaturePointId::from_parts(2, 14);
    /// 3.1: Centre of the left upper eyelid (inner edge touching the eye).
    pub const FP_3_1: FeaturePointId = FeaturePointId::from_parts(3, 1);
    /// 3.2: Centre of the right upper eyelid (inner edge touching the eye).
    pub const FP_3_2: FeaturePointId = FeaturePointId::from_parts(3, 2);
    /// 3.3: Centre of the left lower eyelid (inner edge touching the eye).
    pub const FP_3_3: FeaturePointId = FeaturePointId::from_parts(3, 3);
    /// 3.4: Centre of the right lower eyelid (inner edge touching the eye).
    pub const FP_3_4: FeaturePointId = FeaturePointId::from_parts(3, 4);
    /// 3.5: Centre of the left pupil.
    pub const FP_3_5: FeaturePointId = FeaturePointId::from_parts(3, 5);
    /// 3.6: Centre of the right pupil.
    pub const FP_3_6: FeaturePointId = FeaturePointId::from_parts(3, 6);
    /// 3.7: Left (outer) corner of the left eye.
    pub const FP_3_7: FeaturePointId = FeaturePointId::from_parts(3, 7);
    /// 3.8: Left (inner) corner of the right eye.
    pub const FP_3_8: FeaturePointId = FeaturePointId::from_parts(3, 8);
    /// 3.9: Centre of the left lower eyelid, outer (skin-side) edge.
    pub const FP_3_9: FeaturePointId = FeaturePointId::from_parts(3, 9);
    /// 3.10: Centre of the right lower eyelid, outer (skin-side) edge.
    pub const FP_3_10: FeaturePointId = FeaturePointId::from_parts(3, 10);
    /// 3.11: Right (inner) corner of the left eye.
    pub const FP_3_11: FeaturePointId = FeaturePointId::from_parts(3, 11);
    /// 3.12: Right (outer) corner of the right eye.
    pub const FP_3_12: FeaturePointId = FeaturePointId::from_parts(3, 12);
    /// 3.13: Centre of the left upper eyelid, outer (skin-side) edge.
    pub const FP_3_13: FeaturePointId = FeaturePointId::from_parts(3, 13);
    /// 3.14: Centre of the right upper eyelid, outer (skin-side) edge.
    pub const FP_3_14: FeaturePointId = FeaturePointId::from_parts(3, 14);
    /// 4.1: Inner end of the left eyebrow (its right corner).
    pub const FP_4_1: FeaturePointId = FeaturePointId::from_parts(4, 1);
    /// 4.2: Inner end of the right eyebrow (its left corner).
    pub const FP_4_2: FeaturePointId = FeaturePointId::from_parts(4, 2);
    /// 4.3: Highest point of the left eyebrow.
    pub const FP_4_3: FeaturePointId = FeaturePointId::from_parts(4, 3);
    /// 4.4: Highest point of the right eyebrow.
    pub const FP_4_4: FeaturePointId = FeaturePointId::from_parts(4, 4);
    /// 4.5: Outer end of the left eyebrow (its left corner).
    pub const FP_4_5: FeaturePointId = FeaturePointId::from_parts(4, 5);
    /// 4.6: Outer end of the right eyebrow (its right corner).
    pub const FP_4_6: FeaturePointId = FeaturePointId::from_parts(4, 6);
    /// 5.1: Centre of the left cheek.
    pub const FP_5_1: FeaturePointId = FeaturePointId::from_parts(5, 1);
    /// 5.2: Centre of the right cheek.
    pub const FP_5_2: FeaturePointId = FeaturePointId::from_parts(5, 2);
    /// 5.3: Left cheek bone.
    pub const FP_5_3: FeaturePointId = FeaturePointId::from_parts(5, 3);
    /// 5.4: Right cheek bone.
    pub const FP_5_4: FeaturePointId = FeaturePointId::from_parts(5, 4);
    /// 6.1: Tip of the tongue.
    pub const FP_6_1: FeaturePointId = FeaturePointId::from_parts(6, 1);
    /// 6.2: Centre of the tongue body.
    pub const FP_6_2: FeaturePointId = FeaturePointId::from_parts(6, 2);
    /// 6.3: Left border of the tongue.
    pub const FP_6_3: FeaturePointId = FeaturePointId::from_parts(6, 3);
    /// 6.4: Right border of the tongue.
    pub const FP_6_4: FeaturePointId = FeaturePointId::from_parts(6, 4);
    /// 7.1: Top of the spine; centre of head rotation.
    pub const FP_7_1: FeaturePointId = FeaturePointId::from_parts(7, 1);
    /// 8.1: Middle of the outer upper lip contour.
    pub const FP_8_1: FeaturePointId = FeaturePointId::from_parts(8, 1);
    /// 8.2: Middle of the outer lower lip contour.
    pub const FP_8_2: FeaturePointId = FeaturePointId::from_parts(8, 2);
    /// 8.3: Left corner of the outer lip contour.
    pub const FP_8_3: FeaturePointId = FeaturePointId::from_parts(8, 3);
    /// 8.4: Right corner of the outer lip contour.
    pub const FP_8_4: FeaturePointId = FeaturePointId::from_parts(8, 4);
    /// 8.5: Outer upper lip contour halfway between 8.3 and 8.1.
    pub const FP_8_5: FeaturePointId = FeaturePointId::from_parts(8, 5);
    /// 8.6: Outer upper lip contour halfway between 8.4 and 8.1.
    pub const FP_8_6: FeaturePointId = FeaturePointId::from_parts(8, 6);
    /// 8.7: Outer lower lip contour halfway between 8.3 and 8.2.
    pub const FP_8_7: FeaturePointId = FeaturePointId::from_parts(8, 7);
    /// 8.8: Outer lower lip contour halfway between 8.4 and 8.2.
    pub const FP_8_8: FeaturePointId = FeaturePointId::from_parts(8, 8);
    /// 8.9: High point of the Cupid's bow, right side.
    pub const FP_8_9: FeaturePointId = FeaturePointId::from_parts(8, 9);
    /// 8.10: High point of the Cupid's bow, left side.
    pub const FP_8_10: FeaturePointId = FeaturePointId::from_parts(8, 10);
    /// 9.1: Left nostril border.
    pub const FP_9_1: FeaturePointId = FeaturePointId::from_parts(9, 1);
    /// 9.2: Right nostril border.
    pub const FP_9_2: FeaturePointId = FeaturePointId::from_parts(9, 2);
    /// 9.3: Tip of the nose.
    pub const FP_9_3: FeaturePointId = FeaturePointId::from_parts(9, 3);
    /// 9.4: Bottom right edge of the nose.
    pub const FP_9_4: FeaturePointId = FeaturePointId::from_parts(9, 4);
    /// 9.5: Bottom left edge of the nose.
    pub const FP_9_5: FeaturePointId = FeaturePointId::from_parts(9, 5);
    /// 9.6: Right upper edge of the nose bone.
    pub const FP_9_6: FeaturePointId = FeaturePointId::from_parts(9, 6);
    /// 9.7: Left upper edge of the nose bone.
    pub const FP_9_7: FeaturePointId = FeaturePointId::from_parts(9, 7);
    /// 9.8: Top of the upper teeth.
    pub const FP_9_8: FeaturePointId = FeaturePointId::from_parts(9, 8);
    /// 9.9: Bottom of the lower teeth.
    pub const FP_9_9: FeaturePointId = FeaturePointId::from_parts(9, 9);
    /// 9.10: Bottom of the upper teeth.
    pub const FP_9_10: FeaturePointId = FeaturePointId::from_parts(9, 10);
    /// 9.11: Top of the lower teeth.
    pub const FP_9_11: FeaturePointId = FeaturePointId::from_parts(9, 11);
    /// 9.12: Middle of the lower edge of the nose bone (nose bump).
    pub const FP_9_12: FeaturePointId = FeaturePointId::from_parts(9, 12);
    /// 9.13: Left lower edge of the nose bone.
    pub const FP_9_13: FeaturePointId = FeaturePointId::from_parts(9, 13);
    /// 9.14: Right lower edge of the nose bone.
    pub const FP_9_14: FeaturePointId = FeaturePointId::from_parts(9, 14);
    /// 9.15: Bottom middle edge of the nose (where the nose meets the upper lip).
    pub const FP_9_15: FeaturePointId = FeaturePointId::from_parts(9, 15);
    /// 10.1: Top of the left ear.
    pub const FP_10_1: FeaturePointId = FeaturePointId::from_parts(10, 1);
    /// 10.2: Top of the right ear.
    pub const FP_10_2: FeaturePointId = FeaturePointId::from_parts(10, 2);
    /// 10.3: Back of the left ear.
    pub const FP_10_3: FeaturePointId = FeaturePointId::from_parts(10, 3);
    /// 10.4: Back of the right ear.
    pub const FP_10_4: FeaturePointId = FeaturePointId::from_parts(10, 4);
    /// 10.5: Bottom of the left ear lobe.
    pub const FP_10_5: FeaturePointId = FeaturePointId::from_parts(10, 5);
    /// 10.6: Bottom of the right ear lobe.
    pub const FP_10_6: FeaturePointId = FeaturePointId::from_parts(10, 6);
    /// 10.7: Lower contact point between the left lobe and the face.
    pub const FP_10_7: FeaturePointId = FeaturePointId::from_parts(10, 7);
    /// 10.8: Lower contact point between the right lobe and the face.
    pub const FP_10_8: FeaturePointId = FeaturePointId::from_parts(10, 8);
    /// 10.9: Upper contact point between the left ear and the face.
    pub const FP_10_9: FeaturePointId = FeaturePointId::from_parts(10, 9);
    /// 10.10: Upper contact point between the right ear and the face.
    pub const FP_10_10: FeaturePointId = FeaturePointId::from_parts(10, 10);
    /// 11.1: Middle of the hairline (hair/forehead border).
    pub const FP_11_1: FeaturePointId = FeaturePointId::from_parts(11, 1);
    /// 11.2: Right end of the hairline.
    pub const FP_11_2: FeaturePointId = FeaturePointId::from_parts(11, 2);
    /// 11.3: Left end of the hairline.
    pub const FP_11_3: FeaturePointId = FeaturePointId::from_parts(11, 3);
    /// 11.4: Top of the skull.
    pub const FP_11_4: FeaturePointId = FeaturePointId::from_parts(11, 4);
    /// 11.5: Hair thickness above 11.4 (top of the hair).
    pub const FP_11_5: FeaturePointId = FeaturePointId::from_parts(11, 5);
    /// 11.6: Back of the skull.
    pub const FP_11_6: FeaturePointId = FeaturePointId::from_parts(11, 6);
}

/// The named constants in table order (for the test that pins them).
#[cfg(test)]
pub(super) const NAMED: [FeaturePointId; 84] = [
    FeaturePointId::FP_2_1,
    FeaturePointId::FP_2_2,
    FeaturePointId::FP_2_3,
    FeaturePointId::FP_2_4,
    FeaturePointId::FP_2_5,
    FeaturePointId::FP_2_6,
    FeaturePointId::FP_2_7,
    FeaturePointId::FP_2_8,
    FeaturePointId::FP_2_9,
    FeaturePointId::FP_2_10,
    FeaturePointId::FP_2_11,
    FeaturePointId::FP_2_12,
    FeaturePointId::FP_2_13,
    FeaturePointId::FP_2_14,
    FeaturePointId::FP_3_1,
    FeaturePointId::FP_3_2,
    FeaturePointId::FP_3_3,
    FeaturePointId::FP_3_4,
    FeaturePointId::FP_3_5,
    FeaturePointId::FP_3_6,
    FeaturePointId::FP_3_7,
    FeaturePointId::FP_3_8,
    FeaturePointId::FP_3_9,
    FeaturePointId::FP_3_10,
    FeaturePointId::FP_3_11,
    FeaturePointId::FP_3_12,
    FeaturePointId::FP_3_13,
    FeaturePointId::FP_3_14,
    FeaturePointId::FP_4_1,
    FeaturePointId::FP_4_2,
    FeaturePointId::FP_4_3,
    FeaturePointId::FP_4_4,
    FeaturePointId::FP_4_5,
    FeaturePointId::FP_4_6,
    FeaturePointId::FP_5_1,
    FeaturePointId::FP_5_2,
    FeaturePointId::FP_5_3,
    FeaturePointId::FP_5_4,
    FeaturePointId::FP_6_1,
    FeaturePointId::FP_6_2,
    FeaturePointId::FP_6_3,
    FeaturePointId::FP_6_4,
    FeaturePointId::FP_7_1,
    FeaturePointId::FP_8_1,
    FeaturePointId::FP_8_2,
    FeaturePointId::FP_8_3,
    FeaturePointId::FP_8_4,
    FeaturePointId::FP_8_5,
    FeaturePointId::FP_8_6,
    FeaturePointId::FP_8_7,
    FeaturePointId::FP_8_8,
    FeaturePointId::FP_8_9,
    FeaturePointId::FP_8_10,
    FeaturePointId::FP_9_1,
    FeaturePointId::FP_9_2,
    FeaturePointId::FP_9_3,
    FeaturePointId::FP_9_4,
    FeaturePointId::FP_9_5,
    FeaturePointId::FP_9_6,
    FeaturePointId::FP_9_7,
    FeaturePointId::FP_9_8,
    FeaturePointId::FP_9_9,
    FeaturePointId::FP_9_10,
    FeaturePointId::FP_9_11,
    FeaturePointId::FP_9_12,
    FeaturePointId::FP_9_13,
    FeaturePointId::FP_9_14,
    FeaturePointId::FP_9_15,
    FeaturePointId::FP_10_1,
    FeaturePointId::FP_10_2,
    FeaturePointId::FP_10_3,
    FeaturePointId::FP_10_4,
    FeaturePointId::FP_10_5,
    FeaturePointId::FP_10_6,
    FeaturePointId::FP_10_7,
    FeaturePointId::FP_10_8,
    FeaturePointId::FP_10_9,
    FeaturePointId::FP_10_10,
    FeaturePointId::FP_11_1,
    FeaturePointId::FP_11_2,
    FeaturePointId::FP_11_3,
    FeaturePointId::FP_11_4,
    FeaturePointId::FP_11_5,
    FeaturePointId::FP_11_6,
];
