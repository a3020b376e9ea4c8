//! Light low-level mouth FAPs for each viseme, so a face without viseme tables (CANDIDE-3,
//! a cloned face whose source had none) still moves its jaw and lips when it speaks.
//!
//! Values are hand-set in FAP units (1024 = one whole unit distance: MNS for the jaw and
//! the vertical and depth lip FAPs, MW for the corner stretch) and kept small, about a third
//! of the mouth–nose distance for the widest `aa`: the aim is readable speech motion, not a
//! measured articulation. Open vowels drop the jaw most; `ou`, `oh`, `CH` and `RR` round
//! and push the lips forward (negative stretch pulls the corners in); `E` and `ih` spread
//! them; `PP` presses the lips together.

use crate::spec::{FapId, Viseme};

/// The FAPs written, in this order in the articulation table's rows.
pub const ARTICULATION_FAPS: [u8; 7] = [3, 4, 5, 6, 7, 16, 17];

/// Per viseme 0..=14: open_jaw, lower_t_midlip, raise_b_midlip, stretch_l_cornerlip,
/// stretch_r_cornerlip, push_b_lip, push_t_lip.
const ARTICULATION: [[f64; 7]; Viseme::COUNT] = [
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],             // 0 sil: rest
    [20.0, 40.0, 40.0, 0.0, 0.0, 0.0, 0.0],          // 1 PP: lips pressed together
    [60.0, 0.0, 20.0, 0.0, 0.0, -20.0, 0.0],         // 2 FF: lower lip up and back to the teeth
    [120.0, 0.0, 0.0, 20.0, 20.0, 0.0, 0.0],         // 3 TH: tongue between slightly parted teeth
    [100.0, 0.0, 0.0, 20.0, 20.0, 0.0, 0.0],         // 4 DD
    [140.0, 0.0, 0.0, 10.0, 10.0, 0.0, 0.0],         // 5 kk
    [80.0, 0.0, 0.0, -60.0, -60.0, 80.0, 80.0],      // 6 CH: rounded, protruded
    [60.0, 0.0, 0.0, 60.0, 60.0, 0.0, 0.0],          // 7 SS: teeth close, lips spread
    [100.0, 0.0, 0.0, 20.0, 20.0, 0.0, 0.0],         // 8 nn
    [80.0, 0.0, 0.0, -40.0, -40.0, 50.0, 50.0],      // 9 RR: slightly rounded
    [320.0, 0.0, 0.0, 20.0, 20.0, 0.0, 0.0],         // 10 aa: widest jaw opening
    [200.0, 0.0, 0.0, 80.0, 80.0, 0.0, 0.0],         // 11 E
    [110.0, 0.0, 0.0, 110.0, 110.0, 0.0, 0.0],       // 12 ih: spread
    [260.0, 0.0, 0.0, -80.0, -80.0, 60.0, 60.0],     // 13 oh: open and rounded
    [100.0, 0.0, 0.0, -140.0, -140.0, 110.0, 110.0], // 14 ou: tight rounding
];

/// The low-level FAP values of `viseme`, as (FAP, value) in [`ARTICULATION_FAPS`] order.
pub fn articulation(viseme: Viseme) -> impl Iterator<Item = (FapId, f64)> {
    let row = ARTICULATION[viseme.number() as usize];
    ARTICULATION_FAPS
        .into_iter()
        .zip(row)
        .filter_map(|(n, v)| FapId::new(n).map(|id| (id, v)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_respect_the_fap_table() {
        for n in 0..Viseme::COUNT as u8 {
            let v = Viseme::new(n).unwrap();
            for (id, value) in articulation(v) {
                assert!(id.info().accepts(value), "viseme {n}: FAP {id} = {value}");
                assert!(
                    value.abs() <= 400.0,
                    "viseme {n}: FAP {id} = {value} is not light"
                );
            }
        }
        let jaw = |n: u8| {
            articulation(Viseme::new(n).unwrap())
                .find(|(id, _)| *id == FapId::OPEN_JAW)
                .unwrap()
                .1
        };
        // Open vowels open the jaw more than closed consonants; silence is rest.
        assert!(jaw(10) > jaw(12) && jaw(12) > jaw(1));
        assert_eq!(jaw(0), 0.0);
    }
}
