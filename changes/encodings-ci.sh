# gltf-transform rewrites test assets (quantize, meshopt, draco, weld, reorder, unweld) for
# tests/gltf_encodings.rs; without it those tests print a note and skip.
npm install --no-audit --no-fund --prefix "$HOME/.cache/fbakit-gltf-transform" @gltf-transform/cli@4.5.1
export GLTF_TRANSFORM_DIR="$HOME/.cache/fbakit-gltf-transform"
export FBAKIT_REQUIRE_GLTF_TRANSFORM=1
