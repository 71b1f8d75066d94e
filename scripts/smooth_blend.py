"""Smooth the keyed motion of objects in a .blend file, headless (pipelines, render farms).

Inside Blender:
    blender --background in.blend --python scripts/smooth_blend.py -- \\
        --objects Cube Camera --scheme jarek --levels 5 --out out.blend
With the bpy wheel (polyscrew importable, e.g. from the built wheel):
    python scripts/smooth_blend.py in.blend --objects Cube --out out.blend

Without --objects every object with an active action is smoothed, and objects that cannot
be (no transform keys, NLA strips, ...) are skipped with a warning. Named objects must all
succeed. The result is saved to --out (or over the input with --in-place). Exit status 0 on
success; on any failure nothing is saved, one line "smooth_blend: error: <reason>" goes to
stderr and the status is 1 (2 for bad command-line options).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROG = "smooth_blend"


class Failure(Exception):
    """A reason to stop, shown as the one-line error."""


class OneLineParser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own error prints the whole usage
        print(f"{PROG}: error: {message}", file=sys.stderr)
        sys.exit(2)


def script_arguments() -> list[str]:
    """Arguments meant for this script: after "--" inside Blender, else all of them."""
    if "--" in sys.argv:
        return sys.argv[sys.argv.index("--") + 1 :]
    return sys.argv[1:]


def parse(argv: list[str]) -> argparse.Namespace:
    parser = OneLineParser(prog=PROG, description=__doc__.splitlines()[0])
    parser.add_argument("blend", nargs="?", type=Path, help="the .blend to open (not needed inside Blender)")
    parser.add_argument("--objects", nargs="+", metavar="NAME", help="objects to smooth (default: all animated)")
    parser.add_argument("--scheme", choices=("four_point", "bspline", "jarek"), default="four_point")
    parser.add_argument("--levels", type=int, default=4, choices=range(0, 11), metavar="0..10")
    parser.add_argument("--timing", choices=("keys", "smooth", "linear"), default="keys")
    parser.add_argument("--closed", choices=("AUTO", "ON", "OFF"), default="AUTO", type=str.upper)
    parser.add_argument("--turns", choices=("AUTO", "BLENDER", "SHORTEST"), default="AUTO", type=str.upper,
                        help="flips the short way, typed spins as Blender plays them (AUTO); every span as "
                        "Blender plays it (BLENDER); the short screw everywhere (SHORTEST)")
    parser.add_argument("--step", type=float, default=1.0, help="frames between baked keys (default 1)")
    parser.add_argument("--frame-range", nargs=2, type=float, metavar=("START", "END"), help="default: the keys' range")
    parser.add_argument("--method", choices=("SCREW", "FEATURE"), default="SCREW", type=str.upper,
                        help="SCREW: screw subdivision (default); FEATURE: feature points (variational)")
    parser.add_argument("--parametrization", choices=("uniform", "centripetal"), default="uniform",
                        help="FEATURE: spacing of the keys along the variational curves")
    parser.add_argument("--stiffness", type=float, metavar="LAMBDA",
                        help="FEATURE: approximate the selected keys (not the first/last of an open "
                        "motion) with this spring stiffness (default: hit every key)")
    target = parser.add_mutually_exclusive_group(required=True)
    target.add_argument("--out", type=Path, help="where to save the result")
    target.add_argument("--in-place", action="store_true", help="save over the opened file")
    args = parser.parse_args(argv)
    if not args.step > 0:
        parser.error(f"--step must be positive, got {args.step:g}")
    if args.stiffness is not None and (args.method != "FEATURE" or not args.stiffness >= 0):
        parser.error("--stiffness needs --method FEATURE and a value >= 0")
    return args


def load_addon():
    """The add-on's bake module: the installed extension when enabled, else this checkout's."""
    for name in list(sys.modules):
        if name.startswith("bl_ext.") and name.endswith(".screwbender"):
            return importlib.import_module(f"{name}.blender.bake")
    sys.path.insert(0, str(ROOT / "addon"))
    try:
        return importlib.import_module("screwbender.blender.bake")
    except ImportError as err:
        raise Failure(
            f"cannot import the add-on ({err}); install the ScrewBender extension or put the polyscrew wheel on PYTHONPATH"
        ) from err


def run(args: argparse.Namespace) -> str:
    import bpy

    if args.blend is not None:
        if not args.blend.is_file():
            raise Failure(f"no such file: {args.blend}")
        bpy.ops.wm.open_mainfile(filepath=str(args.blend))
    elif not bpy.data.filepath:
        raise Failure("no .blend given and none open")
    bake = load_addon()

    if args.objects:
        missing = [name for name in args.objects if name not in bpy.data.objects]
        if missing:
            raise Failure(f"no object named {', '.join(missing)} in {bpy.data.filepath}")
        objects = [bpy.data.objects[name] for name in args.objects]
    else:
        objects = [o for o in bpy.data.objects if o.animation_data is not None and o.animation_data.action is not None]
        if not objects:
            raise Failure(f"no animated object in {bpy.data.filepath}")
    objects.sort(key=lambda o: o.name)  # the operator's order

    options = bake.Options(
        scheme=args.scheme,
        levels=args.levels,
        timing=args.timing,
        closed=args.closed,
        turns=args.turns,
        frame_range=tuple(args.frame_range) if args.frame_range else None,
        step=args.step,
        method=args.method,
        parametrization=args.parametrization,
        approximate=args.stiffness is not None,
        stiffness=args.stiffness if args.stiffness is not None else 1.0,
    )
    try:
        # named objects must all be smoothable (checked before anything changes)
        result = bake.smooth(objects, options, strict=bool(args.objects))
    except bake.SmoothError as err:
        raise Failure(str(err)) from err
    actions, skipped = result.actions, result.skipped
    for message in skipped:
        print(f"{PROG}: warning: {message}", file=sys.stderr)
    if not actions:
        raise Failure("nothing smoothed: " + "; ".join(skipped))

    target = Path(bpy.data.filepath) if args.in_place else args.out.resolve()
    target.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(target))
    return f"{PROG}: smoothed {len(result.objects)} object(s) ({args.scheme}, {args.levels} levels) into {target}"


def main() -> int:
    args = parse(script_arguments())
    try:
        print(run(args))
    except Failure as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 1
    except Exception as err:  # anything unexpected still ends in one line and a status
        print(f"{PROG}: error: {type(err).__name__}: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
