"""Render the frames of a `meniscus run` with Blender (3.4 or later; Debian's `blender` package).

    blender -b --python tools/blender/render.py -- OUT_DIR [--frame N] [--png FILE] [--volume]
        [--no-mesh] [--size WxH] [--samples N] [--blend FILE] [--report FILE]

OUT_DIR is a folder `meniscus run` wrote. Everything the script needs about the run comes from
OUT_DIR/meniscus.json (the run's sidecar), never from guesses: the length unit (the scene's unit
becomes Blender's display unit, one Blender unit = one file unit), the frame rate, the file
patterns, which phase the surface encloses, and the half-voxel offset of Blender's volumes.

- The PLY frames become one mesh object per frame, each visible on its own frame only (Blender
  frame N = run frame N), so the animation plays and renders as a sequence; the PLY's vertex
  velocities become the mesh attribute `velocity` (units per second), which Blender's own PLY
  import would drop.
- `--volume` adds the VDB frames as a volume sequence on the same frames (its `density` grid,
  shaded by a Principled Volume), moved by the sidecar's `blender_offset` (Blender draws voxel
  (i, j, k) as the cube [i, i+1]·h where OpenVDB puts its value at i·h). `--no-mesh` leaves the
  meshes out (a volume-only render).
- The camera looks at the bounding box of all frames from above and in front, so every frame of
  the run is framed the same way. Water is a glass material of index 1.333; when the surface
  encloses gas (bubbles: `inside` is "gas" in the sidecar), the same material gets index
  1/1.333, air inside water as seen from the water.
- The camera sees a plain dark background; reflections and refractions see a sky and a checker
  ground, so the refraction shows.
- Cycles on the CPU; denoising is turned off when the build lacks OpenImageDenoise (Debian's).

Without --frame every frame is rendered to OUT_DIR/render/frame_NNNN.png; with --frame N only
frame N, to --png FILE (default OUT_DIR/render_NNNN.png). --blend FILE saves the scene for
interactive use; --report FILE writes JSON with the image size and, per rendered frame, the
pixel bounding box of that frame's mesh as the camera projects it (x right, y down).
"""

import argparse
import json
import math
import os
import sys

import bpy
import numpy as np
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

WATER_IOR = 1.333
# Camera: looking at the box centre from this direction (x, y, z), with this vertical field of
# view; the projection of the run's bounding box fills FILL of the picture's width or height.
VIEW_DIRECTION = (0.35, -1.0, 0.3)
FIELD_OF_VIEW_DEGREES = 35.0
FILL = 0.8
FRAMING_ITERATIONS = 4
# Camera-visible background (linear RGB) and the environment seen in reflections.
BACKGROUND = (0.02, 0.025, 0.03)
SKY_HORIZON = (0.9, 0.92, 0.95)
SKY_ZENITH = (0.3, 0.45, 0.8)
GROUND_A = (0.18, 0.17, 0.16)
GROUND_B = (0.42, 0.4, 0.38)
GROUND_CHECKS = 3.0  # checker squares per unit of (x, y)/−z on the ground plane
# Optical depth of the volume across the box's smallest extent.
VOLUME_OPTICAL_DEPTH = 3.0
BLENDER_LENGTH_UNITS = {"m": "METERS", "cm": "CENTIMETERS", "mm": "MILLIMETERS"}
PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
             "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
             "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
             "float64": "f8"}


def parse_arguments(argv):
    argv = argv[argv.index("--") + 1:] if "--" in argv else []
    p = argparse.ArgumentParser(prog="blender -b --python tools/blender/render.py --",
                                description="Render a meniscus run folder.")
    p.add_argument("out_dir", help="folder written by `meniscus run` (holds meniscus.json)")
    p.add_argument("--frame", type=int, help="render only this frame")
    p.add_argument("--png", help="output PNG of --frame (default OUT_DIR/render_NNNN.png)")
    p.add_argument("--volume", action="store_true", help="add the VDB `density` volume")
    p.add_argument("--no-mesh", action="store_true", help="leave out the PLY meshes")
    p.add_argument("--size", default="960x540", help="image size WxH in pixels")
    p.add_argument("--samples", type=int, default=64, help="Cycles samples per pixel")
    p.add_argument("--blend", help="also save the scene as this .blend file")
    p.add_argument("--report", help="write image size and projected mesh boxes as JSON")
    args = p.parse_args(argv)
    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        p.error("--size: expected WxH, e.g. 640x360, got " + args.size)
    args.width, args.height = width, height
    if args.no_mesh and not args.volume:
        p.error("--no-mesh needs --volume (nothing would be rendered)")
    return args


def read_sidecar(out_dir):
    path = os.path.join(out_dir, "meniscus.json")
    if not os.path.exists(path):
        raise SystemExit(path + ": missing; is this a folder written by `meniscus run`?")
    with open(path) as f:
        return json.load(f)


def read_ply(path):
    """Vertices (n×3), triangles (m×3) and vertex velocities (n×3 or None) of a binary
    little-endian or ASCII PLY triangle mesh with its vertex element first (as meniscus writes)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    fmt = next(l.split()[1] for l in lines if l.startswith("format"))
    elements = []
    for line in lines:
        words = line.split()
        if not words:
            continue
        if words[0] == "element":
            elements.append({"name": words[1], "count": int(words[2]), "props": []})
        elif words[0] == "property":
            elements[-1]["props"].append(words[1:])
    vertex = next(e for e in elements if e["name"] == "vertex")
    face = next(e for e in elements if e["name"] == "face")
    names = [p[-1] for p in vertex["props"]]
    if fmt == "ascii":
        rows = data[end:].decode("ascii").split("\n")
        v = np.array([[float(x) for x in r.split()] for r in rows[:vertex["count"]]])
        f = np.array([[int(x) for x in r.split()[1:4]]
                      for r in rows[vertex["count"]:vertex["count"] + face["count"]]])
    elif fmt == "binary_little_endian":
        vdtype = np.dtype([(n, "<" + PLY_TYPES[p[0]]) for n, p in zip(names, vertex["props"])])
        v = np.frombuffer(data, vdtype, vertex["count"], end)
        v = np.stack([v[n].astype(np.float64) for n in names], axis=1)
        count_type, index_type = (PLY_TYPES[t] for t in face["props"][0][1:3])
        fdtype = np.dtype([("n", "<" + count_type), ("i", "<" + index_type, 3)])
        fr = np.frombuffer(data, fdtype, face["count"], end + vdtype.itemsize * vertex["count"])
        if face["count"] and not np.all(fr["n"] == 3):
            raise SystemExit(path + ": only triangle meshes are supported")
        f = fr["i"].astype(np.int64)
    else:
        raise SystemExit(path + ": unsupported PLY format " + fmt)
    xyz = v[:, [names.index(c) for c in "xyz"]]
    velocity = v[:, [names.index(c) for c in ("vx", "vy", "vz")]] if "vx" in names else None
    return xyz, f.reshape(-1, 3), velocity


def frame_file(out_dir, sidecar, key, frame):
    pattern = sidecar["files"].get(key)
    return os.path.join(out_dir, pattern % frame) if pattern else None


def reset_scene(sidecar, args):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    units = scene.unit_settings
    units.system = "METRIC"
    units.scale_length = sidecar["metres_per_unit"]
    units.length_unit = BLENDER_LENGTH_UNITS[sidecar["length_unit"]]
    rate = float(sidecar["frame_rate"])
    scene.render.fps = max(1, min(32767, round(rate)))
    scene.render.fps_base = scene.render.fps / rate
    scene.frame_start = 0
    scene.frame_end = max(0, sidecar["frame_count"] - 1)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.max_bounces = 16
    scene.cycles.transmission_bounces = 16
    scene.cycles.transparent_max_bounces = 16
    scene.cycles.volume_bounces = 2
    scene.cycles.caustics_reflective = False
    scene.cycles.caustics_refractive = False
    scene.cycles.seed = 0
    import _cycles  # Blender's own module: which optional libraries this build has
    denoise = bool(getattr(_cycles, "with_openimagedenoise", False))
    scene.cycles.use_denoising = denoise
    scene.cycles.use_preview_denoising = denoise
    scene.render.resolution_x = args.width
    scene.render.resolution_y = args.height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    return scene


def make_world(scene):
    world = bpy.data.worlds.new("meniscus environment")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputWorld")
    coords = nodes.new("ShaderNodeTexCoord")
    xyz = nodes.new("ShaderNodeSeparateXYZ")
    links.new(coords.outputs["Generated"], xyz.inputs[0])
    # Sky: horizon to zenith by the direction's height.
    sky = nodes.new("ShaderNodeValToRGB")
    sky.color_ramp.elements[0].color = (*SKY_HORIZON, 1.0)
    sky.color_ramp.elements[1].color = (*SKY_ZENITH, 1.0)
    links.new(xyz.outputs["Z"], sky.inputs["Fac"])
    # Ground: a checker on the plane below, (x, y) / −z of the direction.
    divide_x = nodes.new("ShaderNodeMath")
    divide_x.operation = "DIVIDE"
    divide_y = nodes.new("ShaderNodeMath")
    divide_y.operation = "DIVIDE"
    minus_z = nodes.new("ShaderNodeMath")
    minus_z.operation = "MULTIPLY"
    minus_z.inputs[1].default_value = -1.0
    links.new(xyz.outputs["Z"], minus_z.inputs[0])
    links.new(xyz.outputs["X"], divide_x.inputs[0])
    links.new(minus_z.outputs[0], divide_x.inputs[1])
    links.new(xyz.outputs["Y"], divide_y.inputs[0])
    links.new(minus_z.outputs[0], divide_y.inputs[1])
    plane = nodes.new("ShaderNodeCombineXYZ")
    links.new(divide_x.outputs[0], plane.inputs["X"])
    links.new(divide_y.outputs[0], plane.inputs["Y"])
    checker = nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = GROUND_CHECKS
    checker.inputs["Color1"].default_value = (*GROUND_A, 1.0)
    checker.inputs["Color2"].default_value = (*GROUND_B, 1.0)
    links.new(plane.outputs[0], checker.inputs["Vector"])
    below = nodes.new("ShaderNodeMath")
    below.operation = "LESS_THAN"
    below.inputs[1].default_value = 0.0
    links.new(xyz.outputs["Z"], below.inputs[0])
    environment = nodes.new("ShaderNodeMixRGB")
    links.new(below.outputs[0], environment.inputs["Fac"])
    links.new(sky.outputs["Color"], environment.inputs["Color1"])
    links.new(checker.outputs["Color"], environment.inputs["Color2"])
    lit = nodes.new("ShaderNodeBackground")
    links.new(environment.outputs["Color"], lit.inputs["Color"])
    plain = nodes.new("ShaderNodeBackground")
    plain.inputs["Color"].default_value = (*BACKGROUND, 1.0)
    # Camera rays see the plain background, every other ray the environment.
    light_path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(light_path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(lit.outputs[0], mix.inputs[1])
    links.new(plain.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], out.inputs["Surface"])


def water_material(inside):
    material = bpy.data.materials.new("water" if inside == "liquid" else "air in water")
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    glass = nodes.new("ShaderNodeBsdfGlass")
    glass.distribution = "SHARP"
    glass.inputs["Color"].default_value = (0.92, 0.97, 1.0, 1.0)
    glass.inputs["IOR"].default_value = WATER_IOR if inside == "liquid" else 1.0 / WATER_IOR
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(glass.outputs[0], out.inputs["Surface"])
    return material


def volume_material(density_scale):
    material = bpy.data.materials.new("density")
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    volume = nodes.new("ShaderNodeVolumePrincipled")
    volume.inputs["Color"].default_value = (0.55, 0.75, 1.0, 1.0)
    volume.inputs["Density"].default_value = density_scale
    volume.inputs["Density Attribute"].default_value = "density"
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(volume.outputs[0], out.inputs["Volume"])
    return material


def mesh_object(name, xyz, triangles, velocity, material):
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(xyz))
    mesh.vertices.foreach_set("co", xyz.astype(np.float32).ravel())
    mesh.loops.add(3 * len(triangles))
    mesh.loops.foreach_set("vertex_index", triangles.astype(np.int32).ravel())
    mesh.polygons.add(len(triangles))
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * len(triangles), 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(triangles), 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    mesh.validate()
    mesh.polygons.foreach_set("use_smooth", np.ones(len(triangles), dtype=bool))
    if velocity is not None:
        attribute = mesh.attributes.new("velocity", "FLOAT_VECTOR", "POINT")
        attribute.data.foreach_set("vector", velocity.astype(np.float32).ravel())
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def show_only_on_frame(obj, frame, first, last):
    """Keyframes obj's visibility: shown on `frame`, hidden on every other frame of the run."""
    for f, hidden in ((frame - 1, True), (frame, False), (frame + 1, True)):
        if f < first or f > last:
            continue
        obj.hide_render = obj.hide_viewport = hidden
        obj.keyframe_insert("hide_render", frame=f)
        obj.keyframe_insert("hide_viewport", frame=f)
    for curve in obj.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = "CONSTANT"


def bounding_box(out_dir, sidecar, frames):
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for frame in frames:
        xyz, _, _ = read_ply(frame_file(out_dir, sidecar, "surface_ply", frame))
        lo, hi = np.minimum(lo, xyz.min(axis=0)), np.maximum(hi, xyz.max(axis=0))
    return lo, hi


def place_camera(scene, lo, hi):
    """A camera looking at the box centre from VIEW_DIRECTION, moved along that line until the
    box's projection fills FILL of the picture's width or height."""
    centre = Vector(((lo + hi) / 2).tolist())
    radius = float(np.linalg.norm(hi - lo)) / 2
    camera_data = bpy.data.cameras.new("camera")
    camera_data.sensor_fit = "VERTICAL"
    camera_data.angle_y = math.radians(FIELD_OF_VIEW_DEGREES)
    camera = bpy.data.objects.new("camera", camera_data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    direction = Vector(VIEW_DIRECTION).normalized()
    distance = 3.0 * radius / math.tan(camera_data.angle_y / 2)
    for _ in range(FRAMING_ITERATIONS):
        camera.location = centre + direction * distance
        camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
        bpy.context.view_layer.update()  # the camera's matrix_world, for world_to_camera_view
        box = projected_box(scene, camera, np.array([lo, hi]))
        extent = max((box[2] - box[0]) / scene.render.resolution_x,
                     (box[3] - box[1]) / scene.render.resolution_y)
        distance *= extent / FILL
    camera.location = centre + direction * distance
    camera_data.clip_start = max(distance - 2 * radius, distance / 1000) / 10
    camera_data.clip_end = (distance + 2 * radius) * 10
    bpy.context.view_layer.update()
    return camera


def add_sun(scene):
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = math.radians(2.0)
    sun.rotation_euler = (math.radians(40), 0.0, math.radians(30))
    scene.collection.objects.link(sun)


def add_volume(out_dir, sidecar, frames, animated, density_scale):
    first = frame_file(out_dir, sidecar, "fields_vdb", frames[0])
    volume = bpy.data.volumes.new("fields")
    volume.filepath = first
    if animated:
        # Blender's sequence frame f loads file number f − frame_start + frame_offset + 1.
        volume.is_sequence = True
        volume.frame_start = frames[0]
        volume.frame_offset = frames[0] - 1
        volume.frame_duration = len(frames)
        volume.sequence_mode = "CLIP"
    volume.materials.append(volume_material(density_scale))
    obj = bpy.data.objects.new("fields", volume)
    obj.location = Vector(sidecar["vdb"]["blender_offset"])
    bpy.context.scene.collection.objects.link(obj)
    return obj


def projected_box(scene, camera, xyz):
    """Pixel bounding box (x right, y down) of points as the camera sees them."""
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    corners = [Vector((x, y, z)) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
               for z in (lo[2], hi[2])]
    ndc = [world_to_camera_view(scene, camera, c) for c in corners]
    w, h = scene.render.resolution_x, scene.render.resolution_y
    xs = [p.x * w for p in ndc]
    ys = [(1.0 - p.y) * h for p in ndc]
    return [min(xs), min(ys), max(xs), max(ys)]


def import_frames(out_dir, sidecar, frames, mesh, volume, density_scale):
    """The run's `frames` as an animation: one mesh object per PLY frame, each shown only on its
    own frame (when `mesh`), and the VDB frames as one volume sequence on the same frames (when
    `volume`). Returns ({frame: vertex positions}, {frame: mesh object}, the volume object or
    None)."""
    meshes, objects, volume_object = {}, {}, None
    if mesh:
        material = water_material(sidecar.get("inside", "liquid"))
        for frame in frames:
            xyz, triangles, velocity = read_ply(frame_file(out_dir, sidecar, "surface_ply", frame))
            obj = mesh_object("surface_%04d" % frame, xyz, triangles, velocity, material)
            if len(frames) > 1:
                show_only_on_frame(obj, frame, frames[0], frames[-1])
            meshes[frame] = xyz
            objects[frame] = obj
    if volume:
        volume_object = add_volume(out_dir, sidecar, frames, len(frames) > 1, density_scale)
    return meshes, objects, volume_object


def main():
    args = parse_arguments(sys.argv)
    out_dir = os.path.abspath(args.out_dir)
    sidecar = read_sidecar(out_dir)
    count = sidecar["frame_count"]
    if count < 1:
        raise SystemExit(out_dir + ": the run has written no frame yet")
    all_frames = list(range(sidecar.get("first_frame", 0), sidecar.get("first_frame", 0) + count))
    if args.frame is not None and args.frame not in all_frames:
        raise SystemExit("--frame %d: the run has frames %d to %d" %
                         (args.frame, all_frames[0], all_frames[-1]))
    if not sidecar["files"].get("surface_ply"):
        raise SystemExit(out_dir + ": the run wrote no PLY frames (/output/ply was false)")
    if args.volume and not sidecar["files"].get("fields_vdb"):
        raise SystemExit(out_dir + ": the run wrote no VDB frames (/output/vdb was false)")
    frames = [args.frame] if args.frame is not None else all_frames

    scene = reset_scene(sidecar, args)
    make_world(scene)
    add_sun(scene)
    lo, hi = bounding_box(out_dir, sidecar, all_frames)
    camera = place_camera(scene, lo, hi)
    meshes, _, _ = import_frames(out_dir, sidecar, frames, not args.no_mesh, args.volume,
                                 VOLUME_OPTICAL_DEPTH / float(np.min(hi - lo)))

    report = {"width": args.width, "height": args.height, "frames": {}}
    for frame in frames:
        xyz = meshes.get(frame)
        if xyz is None:
            xyz, _, _ = read_ply(frame_file(out_dir, sidecar, "surface_ply", frame))
        report["frames"][str(frame)] = {"mesh_box": projected_box(scene, camera, xyz)}

    if args.blend:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.blend))
    if args.frame is not None:
        png = os.path.abspath(args.png or os.path.join(out_dir, "render_%04d.png" % args.frame))
        scene.frame_set(args.frame)
        scene.render.filepath = png
        bpy.ops.render.render(write_still=True)
        report["frames"][str(args.frame)]["png"] = png
    else:
        scene.render.filepath = os.path.join(out_dir, "render", "frame_")
        bpy.ops.render.render(animation=True)
    if args.report:
        with open(args.report, "w") as f:
            json.dump(report, f, indent=2)


if __name__ == "__main__":
    main()
