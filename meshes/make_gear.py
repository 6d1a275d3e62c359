"""An involute spur gear as a closed triangle mesh (STL in mm).

    python meshes/make_gear.py --module 2 --teeth 20 --width 10 -o meshes/gear_m2_z20.stl

The standard full-depth profile: pitch radius r = m z / 2, pressure angle
alpha (20° by default), base radius r_b = r cos(alpha), addendum m (tip
radius r + m), dedendum 1.25 m (root radius r - 1.25 m), tooth thickness
pi m / 2 on the pitch circle, no backlash, no tip or root fillet (below the
base circle the flank runs to the root slightly slanted). A flank
point at radius rho lies at the involute angle inv(arccos(r_b / rho)),
inv(phi) = tan(phi) - phi, from the point where the involute leaves the
base circle; below the base circle the flank runs radially to the root.

The outline is star-shaped about the gear's centre (each ray from the
centre crosses it once), so the two end faces are fans from the centre and
the sides are quads between them: no polygon triangulation library needed.
The gear's axis is z, its end faces at z = 0 and z = width, tooth 0 centred
on +x.
"""

import argparse
from pathlib import Path

import numpy as np


def involute(phi):
    """inv(phi) = tan(phi) - phi."""
    return np.tan(phi) - phi


def outline(module, teeth, pressure_angle=20.0, flank_points=16, tip_points=4, root_points=4):
    """(k, 2) points of the gear's outline (mm), counter-clockwise, tooth 0
    centred on +x."""
    alpha = np.radians(pressure_angle)
    r = 0.5 * module * teeth
    rb, ra, rf = r * np.cos(alpha), r + module, r - 1.25 * module
    # half the tooth's angular thickness at radius rho
    half_pitch = np.pi / (2.0 * teeth) + involute(alpha)

    def half_angle(rho):
        return half_pitch - involute(np.arccos(np.minimum(rb / rho, 1.0)))

    start = max(rf, rb)
    rho = np.linspace(start, ra, flank_points)
    flank = half_angle(rho)
    points = []
    gap = 2.0 * np.pi / teeth
    # below the base circle the flank runs to the root with a slight slant
    # (a fifth of the root space's half angle: no two outline points on one
    # ray, so the end-face fans have no flat triangle)
    slant = 0.2 * (0.5 * gap - half_angle(start)) if rf < rb else 0.0
    for k in range(teeth):
        centre = k * gap
        # root arc from the middle of the gap before the tooth to its right flank
        right_root = centre - half_angle(start) - slant
        left_root_prev = centre - gap + half_angle(start) + slant
        for a in np.linspace(0.5 * (left_root_prev + right_root), right_root, root_points,
                             endpoint=False):
            points.append((rf * np.cos(a), rf * np.sin(a)))
        if rf < rb:
            # radial flank below the base circle
            points.append((rf * np.cos(right_root), rf * np.sin(right_root)))
        # right flank (the side at smaller angle), up to the tip
        for rr, h in zip(rho, flank):
            points.append((rr * np.cos(centre - h), rr * np.sin(centre - h)))
        # tip arc
        for a in np.linspace(centre - flank[-1], centre + flank[-1], tip_points + 2)[1:-1]:
            points.append((ra * np.cos(a), ra * np.sin(a)))
        # left flank, down
        for rr, h in zip(rho[::-1], flank[::-1]):
            points.append((rr * np.cos(centre + h), rr * np.sin(centre + h)))
        left_root = centre + half_angle(start) + slant
        if rf < rb:
            points.append((rf * np.cos(left_root), rf * np.sin(left_root)))
        right_root_next = centre + gap - half_angle(start) - slant
        for a in np.linspace(left_root, 0.5 * (left_root + right_root_next), root_points,
                             endpoint=False)[1:]:
            points.append((rf * np.cos(a), rf * np.sin(a)))
    out = np.array(points)
    # drop repeated points (a flank starting where the root arc ends)
    keep = np.ones(len(out), bool)
    keep[1:] = np.linalg.norm(np.diff(out, axis=0), axis=1) > 1e-9 * module
    return out[keep]


def gear_mesh(module, teeth, width, pressure_angle=20.0, flank_points=16, layers=1):
    """(vertices (n, 3), faces (m, 3)) of the gear, mm, outward winding; the
    flanks in ``layers`` rows of quads across the face width (the contact
    points of a worn gear along its width)."""
    ring = outline(module, teeth, pressure_angle, flank_points)
    k = len(ring)
    rings = [np.column_stack([ring, np.full(k, width * level / layers)])
             for level in range(layers + 1)]
    vertices = np.vstack(rings + [[[0.0, 0.0, 0.0]], [[0.0, 0.0, float(width)]]])
    c0, c1 = (layers + 1) * k, (layers + 1) * k + 1
    j = np.arange(k)
    n = (j + 1) % k
    top = layers * k
    faces = [np.column_stack([np.full(k, c0), n, j]),              # bottom, facing -z
             np.column_stack([np.full(k, c1), top + j, top + n])]  # top, facing +z
    for level in range(layers):                                   # sides, facing out
        lo, hi = level * k, (level + 1) * k
        faces += [np.column_stack([lo + j, lo + n, hi + n]),
                  np.column_stack([lo + j, hi + n, hi + j])]
    return vertices, np.vstack(faces).astype(np.int64)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--module", type=float, required=True, help="module m (mm)")
    parser.add_argument("--teeth", type=int, required=True, help="number of teeth z")
    parser.add_argument("--width", type=float, required=True, help="face width (mm)")
    parser.add_argument("--pressure-angle", type=float, default=20.0, help="degrees (20)")
    parser.add_argument("--flank-points", type=int, default=16,
                        help="points along each flank (16)")
    parser.add_argument("--layers", type=int, default=1,
                        help="rows of faces across the face width (1)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="STL file to write")
    args = parser.parse_args()
    if args.teeth < 6 or args.module <= 0.0 or args.width <= 0.0 or args.layers < 1:
        parser.error("need teeth >= 6, module > 0, width > 0 and layers >= 1")
    import trimesh

    vertices, faces = gear_mesh(args.module, args.teeth, args.width, args.pressure_angle,
                                args.flank_points, args.layers)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.export(args.output)
    print(f"{args.output}: {len(vertices)} vertices, {len(faces)} faces, "
          f"pitch diameter {args.module * args.teeth:g} mm, watertight {mesh.is_watertight}")


if __name__ == "__main__":
    main()
