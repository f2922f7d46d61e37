"""Inside Blender: the volume lines up with the mesh, on the right frames. Imports a
`meniscus run`'s frames as render.py does for a whole run — one mesh object per PLY, an animated
volume sequence moved by the sidecar's half-voxel `blender_offset` — and for each FRAME checks
that only the mesh of that frame is shown and that Blender loads fields_FRAME (its own
sequence import would put fields_N on frame N + 1); then turns the `surface` grid back into a
mesh with Blender's own Volume to Mesh modifier (threshold 0) and compares that mesh's bounding
box with the PLY's: every side within half a voxel.

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
    bpy.ops.wm.read_factory_settings(use_empty=True)
    run_frames = list(range(sidecar.get("first_frame", 0),
                            sidecar.get("first_frame", 0) + sidecar["frame_count"]))
    _, surfaces, volume = render.import_frames(run_dir, sidecar, run_frames, True, True, 1.0)
    mesh = bpy.data.objects.new("surface from volume", bpy.data.meshes.new("v2m"))
    bpy.context.scene.collection.objects.link(mesh)
    modifier = mesh.modifiers.new("volume to mesh", "VOLUME_TO_MESH")
    modifier.object = volume
    modifier.grid_name = "surface"
    modifier.threshold = 0.0
    modifier.adaptivity = 0.0
    for frame in frames:
        bpy.context.scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        grids = volume.evaluated_get(depsgraph).data.grids
        grids.load()
        shown = sorted(obj.name for obj in surfaces.values() if not obj.hide_render)
        print("[ measured ] frame %d: meshes shown %s" % (frame, shown))
        if shown != ["surface_%04d" % frame]:
            failures.append("frame %d: meshes shown %s" % (frame, shown))
        loaded = os.path.basename(grids.frame_filepath)
        expected = os.path.basename(render.frame_file(run_dir, sidecar, "fields_vdb", frame))
        print("[ measured ] frame %d: Blender's volume sequence loads %s" % (frame, loaded))
        if loaded != expected:
            failures.append("frame %d: the volume sequence loads %s, not %s" %
                            (frame, loaded, expected))
            continue
        evaluated = mesh.evaluated_get(depsgraph).to_mesh()
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
