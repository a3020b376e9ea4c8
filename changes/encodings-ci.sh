# gltf-transform (npm @gltf-transform/cli) rewrites test assets the way users' tools do
# (quantize, meshopt, draco, weld, reorder, unweld) for tests/gltf_encodings.rs; without
# node/npm or the registry those tests print a skip note instead.
if command -v npm >/dev/null 2>&1; then
  if npm install --silent --no-audit --no-fund --prefix target/gltf-transform @gltf-transform/cli@4.5.1 >/dev/null 2>&1; then
    export GLTF_TRANSFORM_DIR="$PWD/target/gltf-transform"
  else
    echo "note: could not install @gltf-transform/cli; the glTF encoding tests will skip" >&2
  fi
fi
