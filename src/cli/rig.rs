//! `fbakit rig info RIG`: what a blendshape rig holds.

use std::path::PathBuf;

use fbakit::error::Result;
use fbakit::rig::{read_rig, Rig};
use serde::Serialize;

use super::{print_json, EXIT_OK};

/// Rig subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum RigCommand {
    /// List a rig's meshes and blend shapes (moved vertices per shape).
    #[command(
        long_about = "Read a blendshape rig and list its meshes (vertices, faces, material \
                      groups) and its blend shapes (default weight, moved vertices). RIG is a \
                      glTF 2.0 file (.glb, .gltf; morph targets named by \
                      mesh.extras.targetNames), a folder holding a neutral OBJ \
                      (generic_neutral_mesh.obj, neutral.obj, ...) and one full-mesh OBJ per \
                      shape, or that neutral OBJ itself.",
        after_help = "Examples:\n  fbakit rig info ../shared/data/ict-facekit\n  \
                      fbakit rig info avatar.glb --json"
    )]
    Info(InfoArgs),
}

/// Arguments of `rig info`.
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// The rig: .glb, .gltf, a folder of OBJs or a neutral .obj.
    pub rig: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Serialize)]
struct MeshInfo<'a> {
    name: &'a str,
    vertices: usize,
    faces: usize,
    materials: Vec<&'a str>,
}

#[derive(Serialize)]
struct ShapeInfo<'a> {
    name: &'a str,
    default_weight: f32,
    moved_vertices: usize,
}

#[derive(Serialize)]
struct RigInfo<'a> {
    name: &'a str,
    vertices: usize,
    meshes: Vec<MeshInfo<'a>>,
    shapes: Vec<ShapeInfo<'a>>,
    warnings: &'a [fbakit::error::Diagnostic],
}

fn info(rig: &Rig) -> RigInfo<'_> {
    RigInfo {
        name: &rig.name,
        vertices: rig.vertex_count(),
        meshes: rig
            .meshes
            .iter()
            .map(|m| {
                let mut materials: Vec<&str> = m
                    .mesh
                    .groups
                    .iter()
                    .filter_map(|g| g.material.as_deref())
                    .collect();
                materials.sort_unstable();
                materials.dedup();
                MeshInfo {
                    name: &m.name,
                    vertices: m.mesh.vertex_count(),
                    faces: m.mesh.face_count(),
                    materials,
                }
            })
            .collect(),
        shapes: rig
            .shapes
            .iter()
            .map(|s| ShapeInfo {
                name: &s.name,
                default_weight: s.default_weight,
                moved_vertices: s.moved_vertex_count(),
            })
            .collect(),
        warnings: &rig.warnings,
    }
}

/// Runs a rig subcommand.
pub fn run(cmd: RigCommand) -> Result<u8> {
    match cmd {
        RigCommand::Info(a) => {
            let rig = read_rig(&a.rig)?;
            super::print_warnings(&rig.warnings);
            let i = info(&rig);
            if a.json {
                print_json(&i)?;
            } else {
                outln!("rig {}: {} vertices", i.name, i.vertices);
                for m in &i.meshes {
                    outln!(
                        "  mesh {:<24} {:>8} vertices {:>8} faces  {}",
                        m.name,
                        m.vertices,
                        m.faces,
                        m.materials.join(" ")
                    );
                }
                outln!("{} shapes:", i.shapes.len());
                for s in &i.shapes {
                    outln!(
                        "  {:<24} weight {:<5} moves {} vertices",
                        s.name,
                        s.default_weight,
                        s.moved_vertices
                    );
                }
            }
        }
    }
    Ok(EXIT_OK)
}
