//! The bundled ICT head's feature points rebound to a glTF layout built from ICT-FaceKit's
//! OBJ (tests that cut that OBJ into primitives of their own).

use std::path::Path;

/// The bundled ICT feature points (OBJ vertex ids: the sample keeps the OBJ's first 24 591
/// vertices in order) as a feature-point CSV with a `mesh` column: each point bound to its
/// vertex in the first primitive holding it, where `prims[k]` lists primitive `k`'s OBJ
/// vertex per glTF vertex and `spec(k)` names its face mesh (`Head/1`, `#0/2`, …).
pub fn csv(prims: &[&[u32]], spec: impl Fn(usize) -> String) -> String {
    let sample =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/faces/ict-head/ict-head-fp.csv");
    let text = std::fs::read_to_string(sample).unwrap();
    let mut out = String::from("fp,vertices,mesh\n");
    for line in text.lines().skip(1) {
        let mut c = line.split(',');
        let (fp, v) = (c.next().unwrap(), c.next().unwrap().parse::<u32>().unwrap());
        let (k, local) = prims
            .iter()
            .enumerate()
            .find_map(|(k, p)| p.iter().position(|&o| o == v).map(|i| (k, i)))
            .unwrap();
        out += &format!("{fp},{local},{}\n", spec(k));
    }
    out
}
