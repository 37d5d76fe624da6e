# Run by tests/cli/export_command_test.cpp in headless Blender 3.4:
#   blender -b --factory-startup --python blender_evaluated_positions.py -- \
#       MODE FPS FRAMES OUT.json FILE [FILE]
# MODE  pc2 | mdd: import FILE (the base .obj, axes Forward +Y / Up +Z: identity) and add a
#       Mesh Cache modifier reading the second FILE (pc2: by frame, mdd: by time at FPS);
#       glb: import FILE with Blender's glTF importer (scene at FPS, so frame k is time k/FPS).
# Writes {"vertices": n, "frames": {"k": [[x, y, z], ...]}}: the evaluated world-space vertex
# positions (modifiers, shape keys and object transform applied) at each of FRAMES (comma-separated).
import json
import sys

import bpy

# Blender 3.4's glTF importer uses numpy.bool, which numpy 1.24 (Debian 12) removed: give
# it back (the alias of the builtin bool it always was) so the importer runs.
try:
    import numpy
    if not hasattr(numpy, "bool") or numpy.bool is not bool:
        numpy.bool = bool
except ImportError:
    pass

arguments = sys.argv[sys.argv.index("--") + 1:]
mode, fps, frames, out_path, files = arguments[0], float(arguments[1]), arguments[2], arguments[3], arguments[4:]
frames = [int(f) for f in frames.split(",")]

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = max(1, round(fps))
scene.render.fps_base = scene.render.fps / fps

if mode in ("pc2", "mdd"):
    bpy.ops.wm.obj_import(filepath=files[0], forward_axis="Y", up_axis="Z")
    obj = bpy.context.selected_objects[0]
    cache = obj.modifiers.new("subflow", "MESH_CACHE")
    cache.cache_format = mode.upper()
    cache.filepath = files[1]
    cache.forward_axis = "POS_Y"
    cache.up_axis = "POS_Z"
    cache.frame_start = 0.0
    cache.time_mode = "FRAME" if mode == "pc2" else "TIME"
elif mode == "glb":
    bpy.ops.import_scene.gltf(filepath=files[0])
    meshes = [o for o in scene.objects if o.type == "MESH"]
    assert len(meshes) == 1, "expected one mesh object, got %d" % len(meshes)
    obj = meshes[0]
else:
    raise SystemExit("unknown mode " + mode)

result = {"frames": {}}
for frame in frames:
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    world = evaluated.matrix_world
    result["frames"][str(frame)] = [list(world @ v.co) for v in mesh.vertices]
    result["vertices"] = len(mesh.vertices)
    evaluated.to_mesh_clear()
with open(out_path, "w") as out:
    json.dump(result, out)
print("subflow: wrote", out_path)
