"""Pictures of a run's folder (``meshwear plot``, docs/outputs.md): a wear map
of each worn part (:mod:`meshwear.output.maps`), wear profiles along a line,
and the force and wear-volume histories, as PNG files (and the profiles as
CSV). The curves are drawn by matplotlib (the ``plots`` extra).
"""

import csv
from pathlib import Path

import numpy as np

from .export import SERIES_SUFFIXES, ExportError, chosen_parts, part_mesh
from .maps import mesh_fields, pyplot, wear_map

#: samples along a profile line
PROFILE_SAMPLES = 400


def plot(out_dir, names=None, dest=None, profile=None, view=None):
    """Write the pictures of the run in ``out_dir``; return the paths written.

    Parameters
    ----------
    names : sequence of str, optional
        Worn parts to draw (default: all of them).
    dest : path, optional
        Folder for the files (default ``out_dir/plots``).
    profile : ((3,), (3,)), optional
        Two points of a line in the part's own frame (m): the wear depth
        under it is written as ``<part>_profile.png`` and ``.csv``.
    view : (3,), optional
        Direction the wear maps look from, in the part's own frame
        (default: :func:`meshwear.output.maps.wear_map`'s choice).
    """
    plt = pyplot()
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        raise ExportError(f"{out_dir}: no such output folder")
    if (out_dir / "sweep.csv").is_file() and not any(
            next(out_dir.glob(f"*{suffix}"), None) for suffix in SERIES_SUFFIXES):
        if names or profile is not None:
            raise ExportError(f"{out_dir}: a sweep's folder: --part and --profile apply to a "
                              "run's folder (one of its run_NNN)")
        dest = Path(dest) if dest is not None else out_dir / "plots"
        dest.mkdir(parents=True, exist_ok=True)
        return [sweep_plot(out_dir / "sweep.csv", dest / "sweep.png", plt)]
    names = chosen_parts(out_dir, names)
    if profile is not None:
        _line(profile)
    if profile is not None and len(names) > 1:
        raise ExportError("--profile: a line is in one part's frame; choose the part with --part "
                          f"(there: {', '.join(names)})")
    dest = Path(dest) if dest is not None else out_dir / "plots"
    dest.mkdir(parents=True, exist_ok=True)
    written = []
    for name in names:
        written.append(wear_map(out_dir, name, dest / f"{name}_wear_map.png", view))
        if profile is not None:
            written += wear_profile(out_dir, name, profile, dest / f"{name}_profile", plt)
    history = out_dir / "history.csv"
    if history.is_file():
        written.append(history_plot(history, names, dest / "history.png", plt))
    return written


def wear_profile(out_dir, name, line, stem, plt):
    """Wear depth at the end under the line ``line`` = (start, end) in the
    part's own frame (m): each sample's nearest point on the unworn part
    (frame 0), the depth interpolated there on the face found. Writes
    ``stem.csv`` (distance, x, y, z, wear_depth, m) and ``stem.png``."""
    import trimesh

    start, end = _line(line)
    unworn, faces, _ = part_mesh(out_dir, name, 0)
    *_, depth, time = mesh_fields(out_dir, name)
    s = np.linspace(0.0, 1.0, PROFILE_SAMPLES)
    samples = start + s[:, None] * (end - start)
    triangles = unworn[faces]
    closest, face = _closest_points(triangles, samples)
    weights = trimesh.triangles.points_to_barycentric(triangles[face], closest)
    weights = np.clip(weights, 0.0, None)
    weights /= weights.sum(axis=1, keepdims=True)
    values = (weights * depth[faces[face]]).sum(axis=1)
    distance = s * np.linalg.norm(end - start)
    with open(f"{stem}.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["distance", "x", "y", "z", "wear_depth"])
        for row in zip(distance, *closest.T, values):
            writer.writerow([repr(float(v)) for v in row])
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(distance * 1e3, values * 1e6, color="C0")
    ax.set_xlabel("distance along the line (mm)")
    ax.set_ylabel("wear depth (µm)")
    ax.set_title(f"{name}: wear profile at t = {time:.6g} s", fontsize=10)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{stem}.png", dpi=120)
    plt.close(fig)
    return [Path(f"{stem}.png"), Path(f"{stem}.csv")]


def sweep_plot(table, path, plt):
    """Each summary figure of a sweep against its first varied key, one line
    per value of its second (the other keys, if any, as they come)."""
    import json

    with open(table, newline="") as f:
        reader = csv.DictReader(f)
        columns = reader.fieldnames or []
        rows = [r for r in reader if r["status"] == "ok"]
    if "status" not in columns:
        raise ExportError(f"{table}: not a sweep table (no status column)")
    keys = columns[1:columns.index("status")]
    figures = [c for c in columns[columns.index("wall_time") + 1:] if c != "message"]
    if not rows or not figures:
        raise ExportError(f"{table}: no finished run to draw")
    try:
        x = np.array([float(r[keys[0]]) for r in rows])
        xlabel = keys[0]
    except ValueError:          # not a number (a vector, a word): the runs in order
        x = np.arange(len(rows), dtype=float)
        xlabel = f"run ({keys[0]})"
    groups = [r[keys[1]] for r in rows] if len(keys) > 1 else [""] * len(rows)
    fig, axes = plt.subplots(len(figures), 1, figsize=(7, 2.4 * len(figures)), sharex=True,
                             squeeze=False)
    for ax, figure in zip(axes[:, 0], figures):
        for k, group in enumerate(dict.fromkeys(groups)):
            pick = np.array([g == group for g in groups])
            y = np.array([float(r[figure]) if r[figure] else np.nan for r in rows])[pick]
            order = np.argsort(x[pick])
            ax.plot(x[pick][order], y[order], "o-", color=f"C{k}",
                    label=f"{keys[1]} = {group}" if group else None)
        ax.set_ylabel(figure, fontsize=8)
        ax.grid(alpha=0.3)
        if len(keys) > 1:
            ax.legend(fontsize=7)
    axes[-1, 0].set_xlabel(xlabel)
    if xlabel.startswith("run ("):
        axes[-1, 0].set_xticks(x, [json.dumps(r[keys[0]])[1:-1] for r in rows], fontsize=7,
                               rotation=20)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _line(line):
    """The two points of a profile line, checked."""
    try:
        start, end = (np.asarray(p, float) for p in line)
    except (TypeError, ValueError):
        raise ExportError("--profile: expected two points x,y,z (m, the part's own frame)") from None
    if not (start.shape == end.shape == (3,) and np.all(np.isfinite([start, end]))):
        raise ExportError("--profile: expected two points x,y,z (m, the part's own frame)")
    if not np.linalg.norm(end - start) > 0.0:
        raise ExportError("--profile: the two points are the same")
    return start, end


def _closest_points(triangles, points, candidates=24):
    """Nearest point of the triangles to each point, and its triangle: the
    exact nearest among the triangles of the ``candidates`` nearest centroids."""
    import trimesh
    from scipy.spatial import cKDTree

    k = min(candidates, len(triangles))
    _, near = cKDTree(triangles.mean(axis=1)).query(points, k=k)
    near = np.asarray(near).reshape(len(points), k)
    on = trimesh.triangles.closest_point(triangles[near.ravel()], np.repeat(points, k, axis=0))
    distance = np.linalg.norm(on - np.repeat(points, k, axis=0), axis=1).reshape(-1, k)
    best = distance.argmin(axis=1)
    rows = np.arange(len(points))
    return on.reshape(-1, k, 3)[rows, best], near[rows, best]


def history_plot(history, names, path, plt):
    """Contact force components and worn volume of each part against time."""
    with open(history, newline="") as f:
        rows = list(csv.DictReader(f))
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, name in enumerate(names):
        mine = [r for r in rows if r["body"] == name]
        if not mine:
            continue
        t = np.array([float(r["time"]) for r in mine])
        for axis, style in zip("xyz", ("-", "--", ":")):
            top.plot(t, [float(r[f"f{axis}"]) for r in mine], style, color=f"C{k}",
                     label=f"{name} f{axis}")
        bottom.plot(t, [float(r["wear_volume"]) * 1e9 for r in mine], color=f"C{k}", label=name)
    top.set_ylabel("contact force (N)")
    bottom.set_ylabel("worn volume (mm³)")
    bottom.set_xlabel("time (s)")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
