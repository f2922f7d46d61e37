"""Inside Blender: the volume lines up with the mesh. For frames of a `meniscus run`, imports the
VDB as render.py does (moved by the sidecar's half-voxel `blender_offset`), turns its `surface`
grid back into a mesh with Blender's own Volume to Mesh modifier (threshold 0), and compares that
mesh's bounding box with the PLY's: every side within half a voxel.

    blender -b --python-exit-code 1 --python tests/render/blender_alignment.py -- \
        RENDER_SCRIPT RUN_DIR FRAME...
"""

import importlib.util
import os
import sys

import bpy
import numpy as np

BOUND_VOXELS = 0.5


def load_render_module(path):
    spec = importlib.util.spec_from_file_location("meniscus_render", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    render = load_render_module(args[0])
    run_dir = os.path.abspath(args[1])
    frames = [int(f) for f in args[2:]]
    sidecar = render.read_sidecar(run_dir)
    voxel = sidecar["vdb"]["voxel_size"]
    failures = []
    for frame in frames:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        volume = render.add_volume(run_dir, sidecar, [frame], False, 1.0)
        mesh = bpy.data.objects.new("surface from volume", bpy.data.meshes.new("v2m"))
        bpy.context.scene.collection.objects.link(mesh)
        modifier = mesh.modifiers.new("volume to mesh", "VOLUME_TO_MESH")
        modifier.object = volume
        modifier.grid_name = "surface"
        modifier.threshold = 0.0
        modifier.adaptivity = 0.0
        bpy.context.scene.frame_set(frame)
        evaluated = mesh.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
        count = len(evaluated.vertices)
        co = np.empty(3 * count)
        evaluated.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3)
        ply, _, _ = render.read_ply(render.frame_file(run_dir, sidecar, "surface_ply", frame))
        if count == 0:
            failures.append("frame %d: Volume to Mesh gave no vertices" % frame)
            continue
        low = (co.min(axis=0) - ply.min(axis=0)) / voxel
        high = (co.max(axis=0) - ply.max(axis=0)) / voxel
        worst = float(max(np.abs(low).max(), np.abs(high).max()))
        print("[ measured ] frame %d: Volume to Mesh of `surface` (%d vertices) vs the PLY's "
              "bounding box: min side %s, max side %s voxels; worst %.3f voxel" %
              (frame, count, np.round(low, 3).tolist(), np.round(high, 3).tolist(), worst))
        if worst > BOUND_VOXELS:
            failures.append("frame %d: bounding boxes %.3f voxel apart" % (frame, worst))
    for f in failures:
        print("FAIL:", f)
    if failures:
        raise SystemExit(1)


main()
