"""Frames written as a .pvd series of .vtp files against one VTKHDF file
(``run.series``): write time per frame and size on disc, for a part the
size of the ball-on-flat fretting example's (41 k vertices, 82 k faces,
its six point fields and pose), the two formats timed in the same run.

    .venv/bin/python benchmarks/series_output.py [--frames 41] [--subdivisions 6]

Prints one row per format: seconds per frame, MB per frame, MB/s written,
vertex-frames/s, and the ratio to the .pvd series (the reference).
"""

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

from meshwear.output.vtk import PVDSeries
from meshwear.output.vtkhdf import VTKHDFSeries


def frame_data(vertices, k, rng):
    """A frame like a worn ball's: the points move, and the fields are zero
    but on the contact patch (the lowest 5 % of the vertices)."""
    n = len(vertices)
    patch = vertices[:, 2] < np.quantile(vertices[:, 2], 0.05)
    state = np.where(patch, rng.integers(1, 3, n), 0).astype(np.int8)
    on = patch.astype(float)
    return (vertices + 1e-6 * k,
            {"wear_depth": 1e-7 * k * rng.random(n) * on, "normal_force": rng.random(n) * on,
             "friction_force": rng.random((n, 3)) * on[:, None], "pressure": rng.random(n) * on,
             "contact_state": state, "friction_work": 1e-3 * k * rng.random(n) * on},
            {"resolved": 1, "origin": rng.random(3), "orientation": [1.0, 0.0, 0.0, 0.0]})


def size_of(folder):
    return sum(p.stat().st_size for p in Path(folder).rglob("*") if p.is_file())


def measure(Series, vertices, faces, frames, repeats):
    times, sizes = [], []
    for _ in range(repeats):
        rng = np.random.default_rng(0)
        data = [frame_data(vertices, k, rng) for k in range(frames)]
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            with Series(out, "ball", faces) as series:
                for k, (points, fields, pose) in enumerate(data):
                    series.write_frame(0.1 * k, points, fields, pose)
            times.append(time.perf_counter() - start)
            sizes.append(size_of(out))
    return statistics.median(times), sizes[0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=41)
    parser.add_argument("--subdivisions", type=int, default=6, help="icosphere: 6 = 40 962 vertices")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    sphere = trimesh.creation.icosphere(subdivisions=args.subdivisions, radius=0.01)
    vertices, faces = np.asarray(sphere.vertices), np.asarray(sphere.faces, dtype=np.int64)
    n = len(vertices)
    print(f"{n} vertices, {len(faces)} faces, {args.frames} frames, median of {args.repeats}")
    print(f"{'series':<22}{'s/frame':>10}{'MB/frame':>10}{'MB/s':>8}{'vertex-frames/s':>17}"
          f"{'time vs .pvd':>14}{'size vs .pvd':>14}")
    reference = None
    for label, Series in ((".pvd + .vtp (zlib)", PVDSeries), (".vtkhdf", VTKHDFSeries)):
        seconds, size = measure(Series, vertices, faces, args.frames, args.repeats)
        reference = reference or (seconds, size)
        print(f"{label:<22}{seconds / args.frames:>10.4f}{size / args.frames / 1e6:>10.2f}"
              f"{size / seconds / 1e6:>8.0f}{n * args.frames / seconds:>17.3g}"
              f"{seconds / reference[0]:>14.2f}{size / reference[1]:>14.2f}")


if __name__ == "__main__":
    main()
