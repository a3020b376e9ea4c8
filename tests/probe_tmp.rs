mod support;
use support::avatar::{self, IrisNodes, Options};
#[test]
fn probe() {
    let d = tempfile::tempdir().unwrap();
    let d = d.path();
    let source = fbakit::face::read("alma").unwrap();
    for wn in [false, true] {
        let opts = Options {
            iris_nodes: Some(IrisNodes { white_nodes: wn }),
            ..Options::default()
        };
        let glb = d.join("a.glb");
        std::fs::write(&glb, avatar::build_with(&opts).to_glb()).unwrap();
        let csv = avatar::fp_csv(&source, d, "");
        let text: String = std::fs::read_to_string(&csv)
            .unwrap()
            .lines()
            .map(|l| {
                let at = |left: bool, id: &str| {
                    let q = avatar::iris_pole(left) * 0.01;
                    format!("{id},{},{},{}\n", q.x, q.y, q.z)
                };
                match l.split(',').next() {
                    Some("3.5") => at(true, "3.5"),
                    Some("3.6") => at(false, "3.6"),
                    _ => format!("{l}\n"),
                }
            })
            .collect();
        std::fs::write(&csv, text).unwrap();
        let target = fbakit::face::read_with(
            &glb,
            &fbakit::face::FaceReadOptions::with_feature_points(Some(&csv)),
        )
        .unwrap()
        .0;
        for id in ["3.5", "3.6"] {
            let (m, v) = target.fp_vertex(id.parse().unwrap()).unwrap();
            eprintln!("{id}: mesh {} vertex {v}", target.meshes[m].name);
        }
        eprintln!(
            "target transforms {:?}",
            target
                .transforms
                .iter()
                .map(|t| (&t.name, t.parent, t.center))
                .collect::<Vec<_>>()
        );
        eprintln!(
            "target meshes {:?}",
            target
                .meshes
                .iter()
                .map(|m| (&m.name, m.transform))
                .collect::<Vec<_>>()
        );
        let out = fbakit::clone::face::clone_face(&source, &target, &Default::default()).unwrap();
        eprintln!(
            "split {:?} parts {:?} rigid {:?}",
            out.report
                .split_parts
                .iter()
                .map(|p| (p.mesh.as_str(), p.part))
                .collect::<Vec<_>>(),
            out.report.target_parts,
            out.report.rigid
        );
        let f = &out.face;
        eprintln!(
            "out transforms {:?}",
            f.transforms
                .iter()
                .map(|t| (&t.name, t.parent, t.center))
                .collect::<Vec<_>>()
        );
        eprintln!(
            "out meshes {:?}",
            f.meshes
                .iter()
                .map(|m| (&m.name, m.transform))
                .collect::<Vec<_>>()
        );
        for t in &f.fat.tables {
            if let fbakit::fat::TableKey::LowLevel(x) = t.key {
                if (23..=26).contains(&x.number()) {
                    for m in &t.meshes {
                        eprintln!(
                            "FAP {} mesh {} nverts {}",
                            x.number(),
                            m.mesh,
                            m.coord_index.len()
                        );
                    }
                    for y in &t.transforms {
                        eprintln!("FAP {} transform {} {:?}", x.number(), y.transform, y.field);
                    }
                }
            }
        }
    }
}
