"""Reads every file of a `meniscus run` of scenes/drop_merge.json with independent readers —
meshio for the PLY frames, pyopenvdb for the VDB frames (Debian's python3-meshio and
python3-openvdb, through /usr/bin/python3) — and checks what a renderer relies on:

- the sidecar meniscus.json describes the files that exist (units, frame rate, patterns, grids);
- every PLY is closed, edge-manifold and consistently oriented (each directed edge once, its
  reverse once; one fan of triangles around every vertex), carries vertex velocities, and
  encloses the volume stats.jsonl records (SI) in the sidecar's unit;
- every VDB holds the sidecar's grids; `surface` is a level set whose trilinear samples at
  every PLY vertex are within a quarter voxel of zero (issue #35 asks for half a voxel) and
  `density`'s within a quarter voxel of ½ (in voxels of offset) — at the folds of a neck freshly
  zipped by a merge (vertices whose incident triangles' normals differ by more than 90°) too,
  where exact distances alone are up to 0.58 voxel off and the writer's vertex pinning brings
  them in (docs/validation.md, part C); the folds' numbers are printed apart;
- `vel` and `pressure` sit on the fluid's cell centres.

Prints the measured numbers per frame. Usage: check_run_files.py RUN_DIR
"""

import json
import os
import sys
from collections import defaultdict

import meshio
import numpy as np
import pyopenvdb as vdb

BOUND_VOXELS = 0.25
CREASE_DEGREES = 90.0
VOLUME_RELATIVE = 1e-9

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def trilinear(accessor, points, voxel):
    """OpenVDB convention: voxel (i, j, k) holds the value at (i, j, k) · voxel."""
    x = points / voxel
    i0 = np.floor(x).astype(int)
    f = x - i0
    out = np.zeros(len(points))
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                w = ((f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1]) *
                     (f[:, 2] if dz else 1 - f[:, 2]))
                values = np.array([accessor.getValue((int(a + dx), int(b + dy), int(c + dz)))
                                   for a, b, c in i0])
                out += w * values
    return out


def manifold_problems(triangles, vertex_count):
    """(directed edges not paired exactly once with their reverse, vertices with several fans)."""
    directed = defaultdict(int)
    for t in triangles:
        for k in range(3):
            directed[(t[k], t[(k + 1) % 3])] += 1
    bad_edges = sum(1 for (a, b), n in directed.items() if n != 1 or directed.get((b, a)) != 1)
    # Fans: a vertex's triangles connected through the edges at that vertex.
    incident = defaultdict(list)
    for ti, t in enumerate(triangles):
        for v in t:
            incident[v].append(ti)
    singular = 0
    for v, tris in incident.items():
        by_edge = defaultdict(list)
        for ti in tris:
            for w in triangles[ti]:
                if w != v:
                    by_edge[w].append(ti)
        parent = {ti: ti for ti in tris}

        def root(x):
            while parent[x] != x:
                x = parent[x]
            return x
        for pair in by_edge.values():
            for other in pair[1:]:
                parent[root(other)] = root(pair[0])
        singular += len({root(ti) for ti in tris}) > 1
    unused = vertex_count - len(incident)
    return bad_edges, singular, unused


def crease_vertices(points, triangles):
    normals = np.cross(points[triangles[:, 1]] - points[triangles[:, 0]],
                       points[triangles[:, 2]] - points[triangles[:, 0]])
    volume = np.einsum("ij,ij->", points[triangles[:, 0]], normals) / 6.0
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    incident = defaultdict(list)
    for ti, t in enumerate(triangles):
        for v in t:
            incident[v].append(ti)
    crease = np.zeros(len(points), dtype=bool)
    limit = np.cos(np.radians(CREASE_DEGREES))
    for v, tris in incident.items():
        n = normals[tris]
        crease[v] = (n @ n.T).min() < limit
    return crease, volume


def main(run_dir):
    with open(os.path.join(run_dir, "meniscus.json")) as f:
        sidecar = json.load(f)
    with open(os.path.join(run_dir, sidecar["files"]["stats"])) as f:
        stats = [json.loads(line) for line in f]
    count = sidecar["frame_count"]
    check(sidecar["complete"], "sidecar: run not complete")
    check(count == len(stats), "sidecar frame_count %d, stats lines %d" % (count, len(stats)))
    check(sidecar["length_unit"] == "mm" and sidecar["metres_per_unit"] == 0.001,
          "sidecar: drop_merge lengths should be in mm")
    check(abs(sidecar["frame_rate"] - 1000.0) < 1e-9, "sidecar: frame rate of drop_merge is 1000")
    grids_expected = sidecar["vdb"]["grids"]
    check(grids_expected == ["surface", "density", "vel", "pressure"], "sidecar grids %s" %
          grids_expected)
    h = sidecar["vdb"]["voxel_size"]
    ramp = sidecar["vdb"]["density_ramp_voxels"]
    cell = sidecar["vdb"]["fluid_cell_size"]
    domain_min = np.array(sidecar["domain"]["min"])
    cube = (1.0 / sidecar["metres_per_unit"]) ** 3
    worst = {"smooth_phi": 0.0, "smooth_density": 0.0, "crease_phi": 0.0, "crease_density": 0.0}
    for frame in range(count):
        ply = os.path.join(run_dir, sidecar["files"]["surface_ply"] % frame)
        mesh = meshio.read(ply)
        points = np.asarray(mesh.points, dtype=np.float64)
        triangles = np.asarray(mesh.cells_dict["triangle"], dtype=np.int64)
        check(all(k in mesh.point_data for k in ("vx", "vy", "vz")),
              "%s: no vertex velocities" % ply)
        bad_edges, singular, unused = manifold_problems(triangles, len(points))
        check(bad_edges == 0 and singular == 0 and unused == 0,
              "%s: %d unpaired directed edges, %d singular vertices, %d unused vertices" %
              (ply, bad_edges, singular, unused))
        crease, volume = crease_vertices(points, triangles)
        recorded = stats[frame]["volume"] * cube
        check(abs(volume - recorded) <= VOLUME_RELATIVE * recorded,
              "%s: volume %.12g, stats.jsonl %.12g" % (ply, volume, recorded))

        path = os.path.join(run_dir, sidecar["files"]["fields_vdb"] % frame)
        grids, _ = vdb.readAll(path)
        by_name = {g.name: g for g in grids}
        check(sorted(by_name) == sorted(grids_expected), "%s: grids %s" % (path, sorted(by_name)))
        surface, density = by_name["surface"], by_name["density"]
        check(surface.gridClass == vdb.GridClass.LEVEL_SET, "%s: surface not a level set" % path)
        check(abs(surface.transform.voxelSize()[0] - h) < 1e-12, "%s: voxel size" % path)
        phi = np.abs(trilinear(surface.getConstAccessor(), points, h)) / h
        offset = np.abs(trilinear(density.getConstAccessor(), points, h) - 0.5) * ramp
        smooth = ~crease
        s_phi, s_den = phi[smooth].max(), offset[smooth].max()
        c_phi = phi[crease].max() if crease.any() else 0.0
        c_den = offset[crease].max() if crease.any() else 0.0
        worst["smooth_phi"] = max(worst["smooth_phi"], s_phi)
        worst["smooth_density"] = max(worst["smooth_density"], s_den)
        worst["crease_phi"] = max(worst["crease_phi"], c_phi)
        worst["crease_density"] = max(worst["crease_density"], c_den)
        print("[ measured ] frame %2d: %4d vertices (%2d on folds), volume %.6f mm3; |phi| at "
              "vertices max %.3f voxel (folds %.3f), density 0.5-offset max %.3f voxel (folds "
              "%.3f)" % (frame, len(points), crease.sum(), volume, s_phi, c_phi, s_den, c_den))
        check(phi.max() <= BOUND_VOXELS and offset.max() <= BOUND_VOXELS,
              "%s: |phi| %.3f / density offset %.3f voxel at a vertex (folds: %.3f / %.3f)" %
              (path, phi.max(), offset.max(), c_phi, c_den))

        vel, pressure = by_name["vel"], by_name["pressure"]
        check(abs(vel.transform.voxelSize()[0] - cell) < 1e-9, "%s: vel voxel size" % path)
        centre = np.array(vel.transform.indexToWorld((0, 0, 0)))
        check(np.allclose(centre, domain_min + 0.5 * cell, atol=1e-9),
              "%s: vel voxel (0,0,0) at %s, not the first cell centre" % (path, centre))
        check(np.allclose(np.array(pressure.transform.indexToWorld((0, 0, 0))), centre,
                          atol=1e-9), "%s: pressure placed unlike vel" % path)
    print("[ measured ] over %d frames: |phi| at vertices %.3f voxel (folds %.3f), density "
          "offset %.3f voxel (folds %.3f)" % (count, worst["smooth_phi"], worst["crease_phi"],
                                             worst["smooth_density"], worst["crease_density"]))
    if failures:
        print("%d failures" % len(failures))
        return 1
    print("all %d frames read by meshio and pyopenvdb and checked" % count)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
