# Imports files into Blender one by one, each into an empty scene, and prints one JSON line per
# file (prefixed `FBAKIT_JSON `, Blender prints its own lines too) of what Blender made of it;
# tests/blender_import.rs asserts on it.
#
#   blender -b --factory-startup --python tests/support/blender_import.py -- FILE...
#
# Exit code 3: numpy missing (callers treat that as "skip").
# .glb/.gltf go through the glTF importer, .obj through the OBJ importer with split_mode='OFF'
# (one object, vertices in the file's order).
import json
import os
import sys
import traceback

# The numpy fix both Blender scripts need lives beside them.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_numpy  # noqa: E402,F401  (exits 3 without numpy)

import bpy  # noqa: E402


def report(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if path.endswith((".glb", ".gltf")):
        bpy.ops.import_scene.gltf(filepath=path)
    elif path.endswith(".obj"):
        bpy.ops.import_scene.obj(
            filepath=path, split_mode="OFF", use_split_objects=False, use_split_groups=False
        )
    else:
        raise ValueError(f"unknown file type: {path}")
    objects = []
    for o in bpy.data.objects:
        item = {"name": o.name, "type": o.type, "parent": o.parent.name if o.parent else None}
        if o.type == "MESH":
            m = o.data
            item["vertices"] = len(m.vertices)
            item["polygons"] = len(m.polygons)
            keys = m.shape_keys.key_blocks if m.shape_keys else []
            item["shapeKeys"] = [k.name for k in keys]
            # Largest offset of each key from the basis: a key imported as all zeros shows here.
            if m.shape_keys:
                basis = keys[0].data
                item["shapeKeyMax"] = [
                    max(
                        (abs(a - b) for p, q in zip(k.data, basis) for a, b in zip(p.co, q.co)),
                        default=0.0,
                    )
                    for k in keys
                ]
            item["armature"] = next(
                (md.object.name for md in o.modifiers if md.type == "ARMATURE" and md.object),
                None,
            )
            item["vertexGroups"] = [g.name for g in o.vertex_groups]
            item["materials"] = [s.material.name if s.material else None for s in o.material_slots]
            item["positions"] = [list(v.co) for v in m.vertices[:3]]
        elif o.type == "ARMATURE":
            item["bones"] = [b.name for b in o.data.bones]
        objects.append(item)
    actions = [
        {"name": a.name, "paths": sorted({c.data_path for c in a.fcurves}), "range": list(a.frame_range)}
        for a in bpy.data.actions
    ]
    images = [{"name": i.name, "size": list(i.size)} for i in bpy.data.images]
    return {"file": path, "objects": objects, "actions": actions, "images": images}


def main():
    argv = sys.argv
    files = argv[argv.index("--") + 1 :] if "--" in argv else []
    for path in files:
        try:
            r = report(path)
        except Exception:  # reported per file; the test names the file and the trace
            r = {"file": path, "error": traceback.format_exc()}
        print("FBAKIT_JSON " + json.dumps(r), flush=True)


main()
