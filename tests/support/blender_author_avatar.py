# Authors a test avatar the way an artist's Blender exports it, so fbakit is tested on a glTF that
# Blender's own exporter wrote (tests/blender_authored.rs):
#
#   blender -b --factory-startup --python tests/support/blender_author_avatar.py -- HEAD.glb FP.json OUT.glb
#
# HEAD.glb is a one-mesh head (the bundled ict-head sample), FP.json its feature points
# ({"2.1": [x, y, z], ...} in glTF coordinates, metres). The avatar gets: an armature
# (Root > Neck > Head > Jaw, LeftEye, RightEye) skinning the head (the chin and lower lip to
# Jaw, the rest to Head), a textured material (a packed PNG), one shape key of the user's own
# ("UserSmirk") and the head's morph targets dropped, a nodding action on the Head bone, a
# camera, and custom properties on the object, the mesh and the scene (glTF extras). Blender
# splits vertices at UV seams and reorders them on export, so the feature points must be
# given to fbakit as positions.
#
# Exit code 3: numpy missing (callers treat that as "skip").
import json
import os
import sys

# The numpy fix both Blender scripts need lives beside them.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_numpy  # noqa: E402,F401  (exits 3 without numpy)

import bpy  # noqa: E402
from mathutils import Vector  # noqa: E402


def blender(p):
    """glTF (Y up) to Blender (Z up) coordinates, as the glTF importer converts them."""
    return Vector((p[0], -p[2], p[1]))


def smoothstep(a, b, x):
    t = min(max((x - a) / (b - a), 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :]
    head_path, fp_path, out_path = argv
    with open(fp_path) as f:
        fp = {k: blender(v) for k, v in json.load(f).items()}

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=head_path)
    head = next(o for o in bpy.context.scene.objects if o.type == "MESH")
    head.name = "Face"
    head.data.name = "FaceMesh"
    bpy.context.view_layer.objects.active = head
    head.select_set(True)
    # The sample's own morph targets are fbakit's; the artist's file has one shape key of its own.
    if head.data.shape_keys:
        head.shape_key_clear()
    head.shape_key_add(name="Basis")
    smirk = head.shape_key_add(name="UserSmirk")
    corner = fp["8.3"]
    for i, v in enumerate(head.data.vertices):
        w = max(0.0, 1.0 - (v.co - corner).length / 0.02)
        smirk.data[i].co = v.co + Vector((0.0, 0.0, 0.004 * w))

    # Textured material: a packed 8x8 PNG, as an artist's base colour map.
    img = bpy.data.images.new("SkinAlbedo", 8, 8)
    img.pixels = [c for i in range(64) for c in ((0.8, 0.6, 0.5, 1.0) if i % 2 else (0.7, 0.5, 0.4, 1.0))]
    img.file_format = "PNG"
    img.pack()
    mat = bpy.data.materials.new("Skin")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    head.data.materials.clear()
    head.data.materials.append(mat)
    if not head.data.uv_layers:
        head.data.uv_layers.new(name="UVMap")

    # Armature: bone positions from the feature points.
    chin, top = fp["2.1"], fp["11.1"] if "11.1" in fp else fp["11.4"]
    mouth = (fp["8.3"] + fp["8.4"]) / 2
    eye_l, eye_r = fp["3.5"], fp["3.6"]
    es = (eye_l - eye_r).length
    arm = bpy.data.armatures.new("RigData")
    rig = bpy.data.objects.new("Rig", arm)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    bones = {}

    def bone(name, a, b, parent=None):
        e = arm.edit_bones.new(name)
        e.head, e.tail = a, b
        if parent:
            e.parent = bones[parent]
        bones[name] = e

    back = Vector((0.0, 0.6 * es, 0.0))  # Blender's +y is the glTF face's back (−z)
    neck = Vector((0.0, mouth.y, chin.z - 0.3 * es)) + back
    bone("Root", neck - Vector((0, 0, 0.5 * es)), neck - Vector((0, 0, 0.2 * es)))
    bone("Neck", neck - Vector((0, 0, 0.2 * es)), neck, "Root")
    bone("Head", neck, Vector((0.0, neck.y, top.z)), "Neck")
    pivot = Vector((0.0, mouth.y + 0.9 * es, (mouth.z + eye_l.z) / 2))
    bone("Jaw", pivot, Vector((0.0, chin.y, chin.z)), "Head")
    depth = Vector((0.0, 0.2 * es, 0.0))
    bone("LeftEye", eye_l + depth, eye_l, "Head")
    bone("RightEye", eye_r + depth, eye_r, "Head")
    bpy.ops.object.mode_set(mode="OBJECT")

    # Skin: the chin, the lower lip and the lower teeth below the mouth corners go with Jaw.
    g_head = head.vertex_groups.new(name="Head")
    g_jaw = head.vertex_groups.new(name="Jaw")
    lip = mouth.z
    span = lip - chin.z
    for v in head.data.vertices:
        front = smoothstep(pivot.y, pivot.y - 0.5 * es, v.co.y)
        w = smoothstep(lip - 0.05 * span, lip - 0.35 * span, v.co.z) * front
        if w > 0.0:
            g_jaw.add([v.index], w, "REPLACE")
        if w < 1.0:
            g_head.add([v.index], 1.0 - w, "REPLACE")
    head.parent = rig
    mod = head.modifiers.new("Armature", "ARMATURE")
    mod.object = rig

    # A nod on the Head bone: the user's own clip.
    rig.animation_data_create()
    action = bpy.data.actions.new("Nod")
    rig.animation_data.action = action
    pb = rig.pose.bones["Head"]
    pb.rotation_mode = "QUATERNION"
    for frame, angle in ((1, 0.0), (12, 0.15), (24, 0.0)):
        pb.rotation_quaternion = (1.0, angle / 2, 0.0, 0.0)
        pb.keyframe_insert("rotation_quaternion", frame=frame)
    pb.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)

    cam = bpy.data.objects.new("FrontCamera", bpy.data.cameras.new("FrontCameraData"))
    cam.location = Vector((0.0, -0.6, mouth.z + 0.05))
    cam.rotation_euler = (1.5708, 0.0, 0.0)
    bpy.context.scene.collection.objects.link(cam)

    head["author"] = "fbakit test"
    head.data["lod"] = 0
    bpy.context.scene["pipeline"] = "blender-authored"

    bpy.ops.export_scene.gltf(
        filepath=out_path,
        export_format="GLB",
        export_extras=True,
        export_cameras=True,
        export_skins=True,
        export_morph=True,
        export_animations=True,
        export_apply=False,
    )


main()
