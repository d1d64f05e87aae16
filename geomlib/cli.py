"""The ``geomlib`` command.

Students:      geomlib grade --impl labs --lab subdivision
Instructors:   geomlib figures | refs build | refs check | stubs build | stubs check | release OUT | grade-all DIR
Anyone:        geomlib info mesh.obj | geomlib view mesh.obj [--html out.html] | geomlib render mesh.obj -o mesh.png
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

EPILOG = """\
examples:
  geomlib figures --out build/figures          regenerate every figure + index.html (instructors)
  geomlib grade --impl labs --lab subdivision  grade your work in labs/ (students)
  geomlib grade --impl labs --lab subdivision --task 2     only Task 2
  geomlib grade --impl path/to/submission --results results.json
  geomlib refs build --lab subdivision         store reference outputs from solutions/
  geomlib stubs build                          regenerate labs/ from solutions/
  geomlib release dist/ --lab subdivision      student bundle + dist/autograder-subdivision.zip
  geomlib grade-all exports/ --lab subdivision --out regrade/   batch grading (instructors)
  geomlib audit --lab subdivision --jobs 2     mutation analysis of the graded tests (instructors)
  geomlib info mesh.obj                        counts, defects (duplicate, degenerate, non-manifold), genus, bbox
  geomlib view mesh.obj                        turn the mesh in a window (needs a display)
  geomlib view mesh.obj --html mesh.html       the same as one self-contained page (works offline)
  geomlib render mesh.off -o mesh.png --wireframe
  geomlib render spot.obj -o spot.png --view three_quarter --forward=-z
"""


def _cmd_figures(a) -> int:
    from geomlib.grading import figures

    out = Path(a.out)
    figs = figures.build_all(out, labs=a.lab, quick=a.quick, progress=True)
    print(f"{len(figs)} figures; open {out / 'index.html'}")
    return 0


def _cmd_info(a) -> int:
    from geomlib import info

    print(info.describe(a.file))
    return 0


def _cmd_view(a) -> int:
    import shlex

    from geomlib import viewer
    from geomlib.validate import MeshError

    if a.html is None and Path(a.file).is_file() and not viewer.has_display():
        # The library's message names its Python call; at the command line, the command to paste.
        page = shlex.quote(Path(a.file).with_suffix(".html").name)
        raise MeshError(
            "no display here (DISPLAY/WAYLAND_DISPLAY unset): write one page that works offline in any "
            f"browser instead: uv run geomlib view {shlex.quote(a.file)} --html {page}"
        )
    out = viewer.view_file(a.file, html=a.html, up=a.up, edges=a.edges)
    if out is not None:
        print(f"wrote {out} (open it in a web browser; it needs no network)")
    return 0


def _cmd_render(a) -> int:
    import numpy as np

    from geomlib import mesh_io, plot, render
    from geomlib.validate import MeshError

    out = Path(a.output)
    if out.suffix.lower() != ".png":
        raise MeshError(f"-o {a.output}: the output must be a .png file")
    if not out.parent.is_dir():
        what = "is not a folder" if out.parent.exists() else "does not exist"
        raise MeshError(f"-o {a.output}: the folder {out.parent} {what}; create it first")
    V, faces = mesh_io.read_mesh(a.file)
    draw = render.render if isinstance(faces, np.ndarray) and faces.shape[1] == 3 else render.render_polygons
    img = draw(
        V,
        faces,
        wireframe=a.wireframe,
        shadows=a.shadows,
        floor=a.shadows,
        size=(a.width, a.height),
        camera=a.view,
        up_axis=a.up,
        forward=a.forward,
    )
    plot.save_png(a.output, img)
    print(f"wrote {a.output}")
    return 0


#: The files ``geomlib refs|stubs build|check`` make from solutions/ (a module of geomlib.grading with
#: ``build(labs)`` and ``check(labs, **check_options)``), and how their reports read: ``built`` with
#: ``{n}`` files written (changed), ``{same}`` unchanged and ``{seconds}``, ``problem`` with one
#: problem ``{p}``, ``stale`` with ``{n}`` problems.
_GENERATED = {
    "refs": dict(
        built="{n} reference file(s) written (changed), {same} unchanged, in {seconds:.1f} s",
        problem="FAIL {p.lab}/{p.case}: {p.message}",
        ok="references OK",
        stale="{n} reference problem(s)",
    ),
    "stubs": dict(
        built="labs/: {n} stub file(s) written (changed), {same} unchanged",
        problem="STALE {p}",
        ok="labs/ is up to date",
        stale="labs/ is stale: run `geomlib stubs build`",
    ),
    "readme": dict(
        built="README.md: {n} file(s) written (changed), {same} unchanged",
        problem="STALE {p}",
        ok="README.md's lab table is up to date",
        stale="README.md's lab table is stale: run `geomlib readme build`",
    ),
}


def _cmd_generated(a) -> int:
    """``build``: regenerate what ``a.command`` makes from solutions/; ``check``: print each difference
    (stubs: with its diff; refs: and every graded test the solutions fail) and exit 1 if there is any."""
    tool = importlib.import_module(f"geomlib.grading.{a.command}")
    report = _GENERATED[a.command]
    labs = [a.lab] if a.lab else None
    if a.action == "build":
        t = time.time()
        files = tool.build(labs)
        print(report["built"].format(n=len(files), same=getattr(files, "unchanged", 0), seconds=time.time() - t))
        return 0
    options = {"grade": not a.no_grade, "outputs": not a.no_rerun} if a.command == "refs" else {"diff": True}
    problems = tool.check(labs, **options)
    for p in problems:
        print(report["problem"].format(p=p))
    print(report["stale"].format(n=len(problems)) if problems else report["ok"])
    return 1 if problems else 0


def _cmd_grade(a) -> int:
    from geomlib.grading.grade import grade

    data = grade(
        a.impl,
        [a.lab] if a.lab else None,
        results=a.results,
        feedback_dir=a.feedback,
        verbose=a.verbose,
        task=a.task,
        part=a.part,
        pictures=a.pictures,
    )
    print("\n".join(data["report"]))
    if a.results:
        print(f"\nwrote {a.results}")
    return 0


def _cmd_release(a) -> int:
    from geomlib.grading import release

    t = time.time()
    try:
        release.release(Path(a.out), a.lab, check=not a.no_check)
    except (release.ReleaseError, OSError) as e:
        print(f"geomlib release: error: {e}", file=sys.stderr)
        return 1
    print(f"released in {time.time() - t:.0f} s into {a.out}")
    return 0


def _cmd_grade_all(a) -> int:
    from geomlib.grading import batch

    try:
        summary = batch.grade_all(Path(a.submissions), a.lab, Path(a.out), jobs=a.jobs, timeout=a.timeout)
    except batch.BatchError as e:
        print(f"geomlib grade-all: error: {e}", file=sys.stderr)
        return 1
    return 0 if summary["graded"] else 1


def _cmd_audit(a) -> int:
    import json

    from geomlib.grading import audit

    try:
        if a.in_order:
            report = audit.in_order(a.lab, jobs=a.jobs, tasks=a.task)
        else:
            report = audit.audit(a.lab, quick=a.quick, jobs=a.jobs, kind=a.kind, sample=a.sample, tasks=a.task,
                                 files=a.file)  # fmt: skip
    except audit.AuditError as e:
        print(f"geomlib audit: error: {e}", file=sys.stderr)
        return 1
    text = audit.in_order_markdown(report) if a.in_order else audit.markdown(report)
    print(text, end="")
    if a.out:
        out, name = Path(a.out), "in-order" if a.in_order else "audit"
        out.mkdir(parents=True, exist_ok=True)
        (out / f"{name}.md").write_text(text)
        (out / f"{name}.json").write_text(json.dumps(report, indent=1, ensure_ascii=False) + "\n")
        print(f"wrote {out / f'{name}.md'} and {out / f'{name}.json'}")
    return 1 if (audit.in_order_failed(report) if a.in_order else audit.failed(report)) else 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="geomlib",
        description="Geometry-processing course framework: figures, grading, references, stubs, release, mesh tools.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    f = sub.add_parser("figures", help="render every lab's figures (and the dataset gallery) with an index page")
    f.add_argument("--lab", action="append", help="only this lab (repeatable); 'gallery' for the datasets")
    f.add_argument("--out", default="build/figures", help="output folder (default: build/figures)")
    f.add_argument("--quick", action="store_true", help="smaller, faster figures (for tests)")
    f.set_defaults(func=_cmd_figures)

    i = sub.add_parser(
        "info",
        help="describe a mesh file: counts, defects (duplicate/degenerate faces, duplicate/unreferenced vertices, "
        "non-manifold edges/vertices), boundary loops, components, genus, bbox",
    )
    i.add_argument("file")
    i.set_defaults(func=_cmd_info)

    v = sub.add_parser("view", help="turn a mesh in 3D: a window, or --html for a self-contained page")
    v.add_argument("file")
    v.add_argument("--html", help="write an interactive page here instead of opening a window")
    v.add_argument("--up", default="y", choices=["y", "z"], help="the mesh's up axis (default y)")
    v.add_argument(
        "--edges", action=argparse.BooleanOptionalAction, default=None, help="draw edges (default: below 20k edges)"
    )
    v.set_defaults(func=_cmd_view)

    r = sub.add_parser("render", help="render an OBJ/OFF/PLY mesh to a PNG")
    r.add_argument("file")
    r.add_argument("-o", "--output", required=True, help="PNG to write")
    r.add_argument("--wireframe", action="store_true", help="overlay the edges")
    r.add_argument("--shadows", action="store_true", help="cast shadows onto a ground plane")
    from geomlib.camera import AXES, VIEWS

    r.add_argument(
        "--view",
        "--camera",
        dest="view",
        default="three_quarter",
        choices=list(VIEWS),
        help="preset viewpoint, relative to the way the model faces (default three_quarter: front, "
        "35 degrees to the viewer's right, 25 degrees up); --camera is the old name",
    )
    r.add_argument(
        "--up", default="y", choices=["y", "z"], help="the mesh's up axis (default y, usual for OBJ/OFF/PLY files)"
    )
    r.add_argument(
        "--forward",
        choices=AXES,
        metavar="{" + ",".join(AXES) + "}",
        help="the axis the model faces (default +z when y is up, -y when z is up); e.g. --forward=-z "
        "for spot, which looks down -z",
    )
    r.add_argument("--width", type=int, default=800)
    r.add_argument("--height", type=int, default=600)
    r.set_defaults(func=_cmd_render)

    rf = sub.add_parser("refs", help="reference outputs: build from solutions/, or check they are reproduced")
    rf.add_argument("action", choices=["build", "check"])
    rf.add_argument("--lab")
    rf.add_argument(
        "--no-grade",
        action="store_true",
        help="check: compare with the references only, without grading the solutions on every graded test",
    )
    rf.add_argument(
        "--no-rerun",
        action="store_true",
        help="check: do not re-run the cases (their inputs, parameters, stored inputs and files are still "
        "checked); for a run whose graded tests compare the solutions with every reference (the test suite)",
    )
    rf.set_defaults(func=_cmd_generated)

    st = sub.add_parser("stubs", help="regenerate labs/ from solutions/, or check labs/ is up to date")
    st.add_argument("action", choices=["build", "check"])
    st.add_argument("--lab")
    st.set_defaults(func=_cmd_generated)

    rd = sub.add_parser(
        "readme", help="write README.md's lab table (labs, topics, points) from the course, or check it"
    )
    rd.add_argument("action", choices=["build", "check"])
    rd.add_argument("--lab", help=argparse.SUPPRESS)  # the table lists every lab
    rd.set_defaults(func=_cmd_generated)

    g = sub.add_parser("grade", help="run the graded tests on an implementation; print scores, write results.json")
    g.add_argument(
        "--impl",
        default=None,
        help="'solutions', 'labs' (your work) or a submission folder: the lab's own folder or the one holding it "
        "(default: solutions if present, else labs)",
    )
    g.add_argument("--lab", help="only this lab")
    g.add_argument("--task", type=int, help="only the tests of this task (the 'Task N' of the stubs)")
    g.add_argument("--part", help='only the tests of this part, as named in the score table ("boundary rules")')
    g.add_argument("--results", help="write Gradescope results.json here")
    g.add_argument("--feedback", default="feedback", help="folder for feedback pictures (default: feedback/)")
    g.add_argument(
        "--pictures",
        choices=("first", "all", "none"),
        default=None,
        help="feedback pictures of the first failure only (default), of every failure, or none",
    )
    g.add_argument("-v", "--verbose", action="store_true")
    g.set_defaults(func=_cmd_grade)

    rl = sub.add_parser("release", help="write the student bundle and one Gradescope autograder zip per lab")
    rl.add_argument("out", help="output folder")
    rl.add_argument("--lab", action="append", help="only this lab (repeatable; default: every lab)")
    rl.add_argument(
        "--no-check",
        action="store_true",
        help="skip grading the solutions (public and hidden tests) before releasing; by default a lab "
        "whose solutions do not score full marks is not released",
    )
    rl.set_defaults(func=_cmd_release)

    ga = sub.add_parser(
        "grade-all", help="grade many submissions of one lab in parallel: a results.json each and one CSV"
    )
    ga.add_argument("submissions", help="a folder per student, or Gradescope's export (submission_metadata.yml)")
    ga.add_argument("--lab", required=True, help="the lab to grade")
    ga.add_argument("--out", required=True, help="output folder: <student>/results.json and scores.csv")
    ga.add_argument("--jobs", type=int, default=None, help="submissions graded at once (default: CPU count, max 4)")
    ga.add_argument("--timeout", type=float, default=1800.0, help="seconds allowed per submission (default 1800)")
    ga.set_defaults(func=_cmd_grade_all)

    au = sub.add_parser(
        "audit", help="mutation analysis: grade mutants of the solutions and report the ones the tests miss"
    )
    au.add_argument("--lab", action="append", help="only this lab (repeatable; default: every lab)")
    au.add_argument("--quick", action="store_true", help="a fixed sample of a few mutants per lab (for CI)")
    au.add_argument("--jobs", type=int, default=1, help="mutants graded at once (default 1)")
    au.add_argument("--kind", choices=("nothing", "operator"), help="only does-nothing or only operator mutants")
    au.add_argument("--sample", type=int, help="a fixed, seeded sample of N mutants per lab (of --kind)")
    au.add_argument("--task", type=int, action="append", help="only the mutants of this task number (repeatable)")
    au.add_argument("--file", action="append", help="only mutants of files whose path has this (repeatable)")
    au.add_argument(
        "--in-order",
        action="store_true",
        help="instead of mutants: for every task N, grade --task N on the solution with Tasks 1..N done and the "
        "later ones stubbed (full marks, no later task's 'not implemented'); --lab, --task, --jobs, --out apply",
    )
    au.add_argument("--out", help="also write audit.md and audit.json (in-order.md/.json) into this folder")
    au.set_defaults(func=_cmd_audit)
    return p


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    a = parser.parse_args(argv)
    if not getattr(a, "func", None):
        parser.print_help()
        return 0
    from geomlib.validate import MeshError

    # Progress lines ("[1/3] bob: 0/151", "[1/9] subdivision ...") as they happen, also into a log file
    # or `| tee`: block-buffered, `grade-all ... > log` showed nothing until every submission was graded.
    if hasattr(sys.stdout, "reconfigure"):
        sys.stdout.reconfigure(line_buffering=True)
    try:
        return a.func(a)
    except (MeshError, FileNotFoundError) as e:
        msg = str(e)
        if msg.startswith(f"{a.command}: "):  # the library names its function already ("view: ...")
            msg = msg[len(a.command) + 2 :]
        print(f"geomlib {a.command}: {msg}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
