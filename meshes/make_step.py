"""Write the STEP fixture meshes/pin_d6_h10_mm.step: a flat-ended pin, 6 mm across
and 10 mm long, its end face on z = 0 and its axis along +z, in millimetres.

Made once with gmsh's OpenCASCADE kernel and committed, so the tests need
neither gmsh nor a CAD system (they read it with the ``cad`` extra, cascadio)::

    pip install gmsh
    python meshes/make_step.py [--radius 3] [--height 10] [-o meshes/pin_d6_h10_mm.step]
"""

import argparse
from pathlib import Path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--radius", type=float, default=3.0, help="mm")
    parser.add_argument("--height", type=float, default=10.0, help="mm")
    parser.add_argument("-o", "--output", type=Path,
                        default=Path(__file__).with_name("pin_d6_h10_mm.step"))
    args = parser.parse_args(argv)

    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("pin")
        gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, args.height, args.radius)
        gmsh.model.occ.synchronize()
        gmsh.write(str(args.output))  # OpenCASCADE writes millimetres
    finally:
        gmsh.finalize()
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
