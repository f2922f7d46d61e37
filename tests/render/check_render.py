"""Renders a `meniscus run` with tools/blender/render.py in Debian's Blender, tiny and with few
samples, and checks the pictures:

    check_render.py BLENDER RENDER_SCRIPT RUN_DIR WORK_DIR mesh     # frame 0 and the last frame
    check_render.py BLENDER RENDER_SCRIPT RUN_DIR WORK_DIR volume   # the last frame, volume only

A picture passes when it differs from the background inside the projected bounding box of the
frame's mesh (render.py's --report, from Blender's own camera) and equals the background far
outside it (the camera sees a plain background; only the surface or volume can change pixels).
"""

import json
import os
import subprocess
import sys

import numpy as np
from PIL import Image

SIZE = (160, 90)
SAMPLES = 8
# A pixel "differs" from the background by more than this (0–255 scale, any channel) ...
DIFFERENT = 8
# ... "equals" it within this; far outside = farther than this fraction of the width from the box.
EQUAL = 3
FAR_FRACTION = 0.1
# Inside the box at least this fraction of pixels must differ (drops are round, boxes square).
MIN_COVERED = 0.25


def render(blender, script, run_dir, png, frame, extra):
    report = png + ".json"
    command = [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", script,
               "--", run_dir, "--frame", str(frame), "--png", png, "--report", report,
               "--size", "%dx%d" % SIZE, "--samples", str(SAMPLES)] + extra
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if result.returncode != 0 or not os.path.exists(png):
        print(result.stdout[-3000:])
        raise SystemExit("blender failed (exit %d): %s" % (result.returncode, " ".join(command)))
    with open(report) as f:
        return json.load(f)["frames"][str(frame)]["mesh_box"]


def check_picture(png, box, what):
    image = np.asarray(Image.open(png).convert("RGB")).astype(int)
    height, width, _ = image.shape
    corners = np.concatenate([image[:4, :4].reshape(-1, 3), image[:4, -4:].reshape(-1, 3),
                              image[-4:, :4].reshape(-1, 3), image[-4:, -4:].reshape(-1, 3)])
    background = np.median(corners, axis=0)
    deviation = np.abs(image - background).max(axis=2)
    x0, y0, x1, y1 = box
    ys, xs = np.mgrid[0:height, 0:width]
    cx, cy = xs + 0.5, ys + 0.5
    inside = (cx >= x0) & (cx <= x1) & (cy >= y0) & (cy <= y1)
    margin = FAR_FRACTION * width
    far = (cx < x0 - margin) | (cx > x1 + margin) | (cy < y0 - margin) | (cy > y1 + margin)
    covered = float((deviation[inside] > DIFFERENT).mean()) if inside.any() else 0.0
    far_max = int(deviation[far].max()) if far.any() else 0
    print("[ measured ] %s: box [%.0f, %.0f]-[%.0f, %.0f] of %dx%d, %.0f %% of its pixels differ "
          "from the background, far outside at most %d/255 off" %
          (what, x0, y0, x1, y1, width, height, 100 * covered, far_max))
    problems = []
    if not (0 <= x0 < x1 <= width and 0 <= y0 < y1 <= height):
        problems.append("%s: the projected box %s is not inside the picture" % (what, box))
    if not far.any():
        problems.append("%s: nothing far outside the box to compare" % what)
    if covered < MIN_COVERED:
        problems.append("%s: only %.0f %% of the box differs from the background" %
                        (what, 100 * covered))
    if far_max > EQUAL:
        problems.append("%s: far outside the box a pixel is %d/255 off the background" %
                        (what, far_max))
    return problems


def main(blender, script, run_dir, work_dir, mode):
    os.makedirs(work_dir, exist_ok=True)
    with open(os.path.join(run_dir, "meniscus.json")) as f:
        last = json.load(f)["frame_count"] - 1
    problems = []
    if mode == "mesh":
        for frame in (0, last):
            png = os.path.join(work_dir, "mesh_%04d.png" % frame)
            box = render(blender, script, run_dir, png, frame, [])
            problems += check_picture(png, box, "mesh frame %d" % frame)
    elif mode == "volume":
        png = os.path.join(work_dir, "volume_%04d.png" % last)
        box = render(blender, script, run_dir, png, last, ["--volume", "--no-mesh"])
        problems += check_picture(png, box, "volume frame %d" % last)
    else:
        raise SystemExit("mode: mesh or volume")
    for p in problems:
        print("FAIL:", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:6]))
