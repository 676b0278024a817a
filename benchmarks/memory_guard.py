"""Peak memory of the ``sandwich`` commands against the guard's estimate (sandwich.models.memory).

Every row runs the real command line (``python -m sandwich.cli solve|mesh ... --quiet``) on a
variant of ``scenes/default.toml`` in its own process and reads that process's peak resident set
size from ``os.wait4`` (``ru_maxrss``, the kernel's high-water mark of the whole process), read
by a small launcher process (:data:`LAUNCHER`). The
beam rows follow a short path (until w_top_mid = UNTIL mm) at a given element count, core
level and contact search (the same-x rows tell the contact term apart: their pattern never
grows); the 2D rows mesh only (``sandwich mesh``) or solve ``max_steps = 2`` steps at a mesh level
and refinement. The 1-minute load average is recorded before and after each row (the machine has
2 cores shared with other jobs: the seconds are indicative, the megabytes are not disturbed).

The measurements are kept in ``benchmarks/results/memory/memory_guard.json`` (or ``--out DIR``),
with the machine and date they were measured on; ``--table`` renders the table again from them
with the current estimate (no solve), so that the constants of the estimate and the table they
were fitted to stay together. From the project root:

    python -m benchmarks.memory_guard            # measure the rows not measured yet, the table
    python -m benchmarks.memory_guard --table    # re-render with the current estimate
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, machine

OUT = RESULTS / "memory"
UNTIL = -0.5  # mm: a short path (a handful of steps)

# Rows: (role, ...). "fit" rows set the constants of sandwich/models/memory.py (least squares on the
# relative error, printed by this script); "check" rows are predicted by that fit, not fitted.
# The beam rows are runs whose tangents the envelope LDLᵀ factorises throughout: a run whose
# LDLᵀ is refused falls back to SuperLU's pivoting LU, which the estimate does not model (on
# this path: 3000-8000 elements at core level 3, 2000 at levels 4 and 5; OUTSIDE_ROWS).
BEAM_ROWS = [  # (role, elements, core, contact search)
    ("fit", 2000, "1", "closest-point"), ("fit", 4000, "1", "closest-point"),
    ("fit", 8000, "1", "closest-point"), ("fit", 8000, "1", "same-x"),
    ("fit", 2000, "2", "closest-point"), ("fit", 1000, "3", "closest-point"),
    ("fit", 2000, "3", "closest-point"), ("fit", 500, "5", "closest-point"),
    ("check", 16000, "1", "closest-point"), ("check", 16000, "1", "same-x"),
    ("check", 4000, "2", "closest-point"), ("check", 500, "4", "closest-point"),
    ("check", 1000, "4", "closest-point"), ("check", 1000, "5", "closest-point"),
    ("check", 1000, "auto", "closest-point"),
]
# Measured with the others, shown apart, neither fitted nor checked: runs that fell back to the
# pivoting LU (counted in one process, SuperLU factorisations made: 1 each).
OUTSIDE_ROWS = [("outside", 4000, "3", "closest-point"), ("outside", 8000, "3", "closest-point"),
                ("outside", 2000, "5", "closest-point")]
TWO_D_ROWS = [  # (role, command, level, refine)
    ("fit", "mesh", "coarse", 0), ("fit", "mesh", "medium", 0), ("fit", "mesh", "coarse", 1),
    ("fit", "mesh", "coarse", 2), ("fit", "mesh", "fine", 1), ("check", "mesh", "coarse", 3),
    ("check", "mesh", "coarse", 6),
    ("fit", "solve", "coarse", 0), ("fit", "solve", "medium", 0), ("fit", "solve", "coarse", 1),
    ("fit", "solve", "coarse", 2), ("fit", "solve", "fine", 0), ("check", "solve", "coarse", 3),
]


def beam_scene(elements: int, core: str, search: str = "closest-point") -> str:
    """The default scene, a short path, ``[beam_model]`` at ``elements``, ``core``, ``search``."""
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = text.replace("value = -8", f"value = {UNTIL}")
    core_value = '"auto"' if core == "auto" else core
    return text + (f"\n[beam_model]\nelements = {elements}\ncore = {core_value}\n"
                   f"contact_search = \"{search}\"\n")


def two_d_scene(level: str, refine: int, steps: int) -> str:
    """The default scene with ``[reference2d]`` at ``level`` + ``refine``, ``steps`` steps.

    The mesh estimate is off: a row is one process's peak (the estimate's coarser path runs in a
    process of its own, added by the guard, not fitted).
    """
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = re.sub(r'^level = "\w+".*$',
                  f'level = "{level}"\nrefine = {refine}\nerror_estimate = false', text,
                  count=1, flags=re.MULTILINE)
    return text.replace("max_steps = 400", f"max_steps = {steps}")


# The command is started by this small launcher process, which reads the command's rusage. Linux
# keeps the high-water RSS across exec, and a child forked (or vforked) from a large process
# (a test run that has loaded FEniCSx) starts with the parent's pages counted: started from a
# fresh small process, the peak is the command's own (+ the launcher's ~10 MB).
LAUNCHER = """import json, os, sys
pid = os.posix_spawn(sys.argv[2], sys.argv[2:], os.environ)
_, status, usage = os.wait4(pid, 0)
with open(sys.argv[1], "w") as fh:
    json.dump({"exit": os.waitstatus_to_exitcode(status), "maxrss_kb": usage.ru_maxrss}, fh)
"""


def measure(argv: list[str], cwd: Path) -> dict:
    """Run ``argv`` (its first item an absolute path) in ``cwd``; exit code, wall seconds, peak
    RSS (bytes), the load before and after, the tails of stdout and stderr."""
    env = {**os.environ, "XDG_CACHE_HOME": str(ROOT / ".cache")}
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    report = cwd / "rusage.json"
    with open(cwd / "stdout.txt", "w") as out, open(cwd / "stderr.txt", "w") as err:
        subprocess.run([sys.executable, "-c", LAUNCHER, str(report), *argv], cwd=cwd,
                       stdout=out, stderr=err, env=env, check=True)
    wall = time.perf_counter() - t0
    usage = json.loads(report.read_text())
    return {"exit": usage["exit"], "wall_s": round(wall, 2),
            "peak_rss_bytes": usage["maxrss_kb"] * 1024, "load_before": round(load0, 2),
            "load_after": round(os.getloadavg()[0], 2),
            "stdout": (cwd / "stdout.txt").read_text()[-2000:],
            "stderr": (cwd / "stderr.txt").read_text()[-2000:]}


def row_id(row: dict) -> tuple:
    if row["kind"] == "beam":
        return ("beam", row["elements"], row["core"], row.get("search", "closest-point"))
    if row["kind"].startswith("2d"):
        return (row["kind"], row["level"], row["refine"])
    return (row["kind"],)


def _solve_info(folder: Path) -> dict:
    summary = folder / "out" / "summary.json"
    return json.loads(summary.read_text()) if summary.is_file() else {}


def run_rows(have: list[dict]) -> list[dict]:
    """Measure every row not in ``have`` (each in a fresh temporary folder); all rows."""
    py = [sys.executable, "-m", "sandwich.cli"]
    done = {row_id(r): r for r in have}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)
        if ("import",) not in done:
            d = base / "validate"
            d.mkdir()
            r = measure([*py, "validate", str(ROOT / "scenes" / "default.toml"), "--quiet"], d)
            done[("import",)] = {"kind": "import", **r}
        rows.append({**done[("import",)], "role": "info"})
        for role, elements, core, search in BEAM_ROWS + OUTSIDE_ROWS:
            key = ("beam", elements, core, search)
            if key not in done:
                d = base / f"beam-{elements}-{core}-{search}"
                d.mkdir()
                (d / "s.toml").write_text(beam_scene(elements, core, search))
                r = measure([*py, "solve", "s.toml", "--model", "beam", "--out", "out",
                             "--quiet"], d)
                info = _solve_info(d)
                done[key] = {
                    "kind": "beam", "elements": elements, "core": core, "search": search,
                    "steps": info.get("steps"), "dofs": info.get("dofs"), **r}
                print("beam", elements, core, search, r["peak_rss_bytes"] / 2**20, r["wall_s"],
                      flush=True)
            rows.append({**done[key], "role": role})
        warm = False
        for role, command, level, refine in TWO_D_ROWS:
            if (f"2d-{command}", level, refine) not in done:
                if not warm:  # the first 2D run compiles its forms (cached after): not measured
                    d = base / "warm-up"
                    d.mkdir()
                    (d / "s.toml").write_text(two_d_scene("coarse", 0, 1))
                    measure([*py, "solve", "s.toml", "--model", "2d", "--out", "out",
                             "--quiet"], d)
                    warm = True
                d = base / f"2d-{command}-{level}-{refine}"
                d.mkdir()
                (d / "s.toml").write_text(two_d_scene(level, refine, 2))
                extra = ["--model", "2d"] if command == "solve" else []
                r = measure([*py, command, "s.toml", *extra, "--out", "out", "--quiet"], d)
                info = _solve_info(d)
                done[(f"2d-{command}", level, refine)] = {
                    "kind": f"2d-{command}", "level": level, "refine": refine,
                    "steps": info.get("steps"), "dofs": info.get("dofs"), **r}
                print(command, level, refine, r["peak_rss_bytes"] / 2**20, r["wall_s"],
                      flush=True)
            rows.append({**done[(f"2d-{command}", level, refine)], "role": role})
    return rows


def scene_of(row: dict):
    """The scene a row ran."""
    import tomllib

    from sandwich.scene_checks import build_scene

    text = (beam_scene(row["elements"], row["core"], row.get("search", "closest-point"))
            if row["kind"] == "beam"
            else two_d_scene(row["level"], row["refine"], 2))
    return build_scene(tomllib.loads(text), "s.toml")


def estimate_of(row: dict, states: int | None = None) -> float | None:
    """The estimate (bytes) for the scene and command of ``row``, with ``states`` kept states
    (default: the scene's step budget, as the guard assumes)."""
    from sandwich.models import memory

    if row["kind"] == "import":
        return None
    what = {"beam": "beam", "2d-mesh": "mesh", "2d-solve": "2d"}[row["kind"]]
    return memory.estimate(scene_of(row), what, states=states).peak_bytes


def fit(rows: list[dict]) -> dict[str, float]:
    """Least squares (relative error) of the constants of sandwich.models.memory, "fit" rows.

    Each row's kept states (8 bytes a DOF each, at the steps it took) and, for the beam, its
    contact term (derived, not fitted) are taken off first.
    """
    import numpy as np

    from sandwich.models import memory

    def solve(kind, *features):
        A, y = [], []
        for r in rows:
            if r["kind"] == kind and r["role"] == "fit":
                scene = scene_of(r)
                states = (r["steps"] or 0) + 1 if kind != "2d-mesh" else 0
                kept = 0.0
                if kind != "2d-mesh":
                    # the states term alone: the estimate with the other constants at zero
                    kept = memory.states_bytes(scene, "beam" if kind == "beam" else "2d", states)
                if kind == "beam":
                    kept += memory.contact_bytes(scene)
                A.append([1.0, *(f(scene) for f in features)])
                y.append(r["peak_rss_bytes"] - kept)
        A, y = np.array(A), np.array(y)
        return np.linalg.lstsq(A / y[:, None], np.ones_like(y), rcond=None)[0]

    b0, e, w = solve("beam", memory.beam_elements, memory.beam_dofs)
    t0, c = solve("2d-solve", lambda s: memory.n_log_n(2 * memory.mesh_size(s)[1]))
    m0, m = solve("2d-mesh", lambda s: memory.mesh_size(s)[0])
    return {"BEAM_BASE": b0, "BEAM_PER_ELEMENT": e, "BEAM_PER_DOF": w, "TWO_D_BASE": t0,
            "TWO_D_PER_DOF": c, "MESH_BASE": m0, "MESH_PER_CELL": m}


def _row_line(r: dict) -> str:
    """One table row: the measured peak next to the estimate at the states kept and the guard's."""
    mib = 2**20
    rss = r["peak_rss_bytes"] / mib
    load = f"{r['load_before']:.2f}/{r['load_after']:.2f}"
    if r["kind"] == "import":
        return f"| validate | (imports only) | | | | {rss:.0f} | | | | {r['wall_s']:.1f} | {load} |"
    if r["kind"] == "beam":
        search = r.get("search", "closest-point")
        what, res = "solve beam", f"{r['elements']} elements, core {r['core']}, {search}"
    else:
        what = "mesh" if r["kind"] == "2d-mesh" else "solve 2d"
        res = f"{r['level']} + refine {r['refine']}"
    kept = (r["steps"] or 0) + 1 if r["kind"] != "2d-mesh" else None
    est, guard = estimate_of(r, kept), estimate_of(r)
    return (f"| {what} | {res} | {r['role']} | {r.get('steps') or ''} | {r.get('dofs') or ''} "
            f"| {rss:.0f} | {est / mib:.0f} | {est / r['peak_rss_bytes']:.2f} | "
            f"{guard / mib:.0f} | {r['wall_s']:.1f} | {load} |")


HEADER = ["| command | resolution | role | steps | DOFs | peak RSS (MiB) | estimate (MiB) | "
          "estimate / measured | guard's estimate (MiB) | wall (s) | load before/after |",
          "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]


def table(rows: list[dict], meta: dict, constants: dict[str, float],
          outside: list[dict] = ()) -> str:
    """Markdown table: measured peak RSS next to the estimate; the runs outside the model."""
    from sandwich.models import memory

    now = {k: getattr(memory, k) for k in constants}
    again = "beam_rows_again" in meta
    where = (f"{meta.get('machine', 'an unnamed machine')}, {meta['date']} (MemTotal "
             f"{meta['mem_total_gb']:.1f} GB" + (f", commit {meta['commit']}" if "commit" in meta
                                                 else "") + ")")
    lines = ["# Peak memory of the command line against the guard's estimate", ""]
    if again:
        lines += [f"Measured on {meta['beam_rows_machine']}, {meta['beam_rows_again']} "
                  f"(MemTotal {meta['beam_rows_mem_total_gb']:.1f} GB"
                  + (f", commit {meta['beam_rows_commit']}" if meta.get("beam_rows_commit")
                     else "") + f"): the beam rows and the import row, with the kernels of the "
                  "ahead-of-time build (no numba in the process). The mesh and 2D rows on "
                  f"{where}.", ""]
    else:
        kernels = {"aot": ", the beam's kernels of the ahead-of-time build (no numba in the "
                          "process)", "jit": ", the beam's kernels under numba's JIT"}
        lines += [f"Measured on {where}{kernels.get(meta.get('kernels'), '')}.", ""]
    lines += [
        "Each row runs the command in its own process, started by `benchmarks/memory_guard.py`'s "
        "launcher; peak RSS = `ru_maxrss` of the command's process (`os.wait4`), on 2-CPU "
        "machines shared with other jobs (load in the last column). Scene: "
        f"`scenes/default.toml`; beam rows to w_top_mid = {UNTIL} mm, 2D solve rows 2 steps "
        "(`max_steps = 2`). Repeated runs of one beam row differ by up to ≈ 35 MiB (4000 "
        "elements, core level 1: 313 and 347 MiB in four runs).", "",
        "Estimate (`sandwich.models.memory`) at the states the run kept (the fit) and as the "
        "guard judges it, with every step of the scene's budget kept (`max_steps = 400` for the "
        "beam rows). Role *fit*: the row set the constants; *check*: predicted, not fitted. The "
        "beam's contact term (closest-point rows) is derived, not fitted; on this short path the "
        "closest-point pattern grows from 8000 elements at core level 1, so below that the term "
        "counts a growth the run does not meet (on the scene's own path to −8 mm it does).", "",
        *HEADER]
    lines += [_row_line(r) for r in rows]
    lines += ["", "Constants fitted to the *fit* rows (in `sandwich/models/memory.py`: "
              + ", ".join(f"`{k}` = {v:.4g}" + ("" if math.isclose(v, now[k], rel_tol=0.01)
                                                 else f" (module: {now[k]:.4g})")
                          for k, v in constants.items())
              + f"); derived: `CONTACT_PER_ENTRY` = {memory.CONTACT_PER_ENTRY:.4g} bytes per "
              "entry of the tangent's pattern."]
    if outside:
        lines += ["", "## Outside the model: runs that fall back to the pivoting LU", "",
                  "Where the pivot-free LDLᵀ of a tangent is refused (a tiny pivot), the beam "
                  "factorises it with SuperLU's pivoting LU, whose factors are several times the "
                  "envelope's; the estimate has no term for it. On this path (SuperLU "
                  "factorisations counted in one process) it happens at 3000-8000 elements at "
                  "core level 3, 8000 at level 2, 2000 at levels 4 and 5, none at level 1 up to "
                  "16000 elements. Measured with the rows above, neither fitted nor checked:",
                  "", *HEADER, *[_row_line(r) for r in outside]]
    bad = [r for r in [*rows, *outside] if r["exit"] not in (0, 1)]
    if bad:
        lines += ["", "Rows that failed: " + ", ".join(f"{r['kind']} exit {r['exit']}"
                                                       for r in bad)]
    return "\n".join(lines) + "\n"


def _commit() -> str:
    """The short commit of the working tree measured ("+" when it has changes)."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True, cwd=ROOT).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True, cwd=ROOT).stdout.strip()
    return head + ("+" if dirty else "")


def main() -> None:
    """Measure the rows not measured yet (or none, ``--table``), fit, write the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--table", action="store_true", help="re-render from the stored JSON")
    ap.add_argument("--again", action="store_true", help="measure every row again")
    ap.add_argument("--again-beam", action="store_true",
                    help="measure the beam rows (and the import row) again, keep the 2D ones")
    add_out_argument(ap, OUT)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    store = args.out / "memory_guard.json"
    data = json.loads(store.read_text()) if store.is_file() and not args.again else None
    mem = Path("/proc/meminfo").read_text()
    total = int(re.search(r"MemTotal:\s+(\d+)", mem).group(1)) * 1024
    if data is not None and args.again_beam:
        data["rows"] = [r for r in data["rows"] if r["kind"] not in ("beam", "import")]
        data["outside"] = []
        data["meta"] = {**data["meta"], "beam_rows_again": time.strftime(
            "%Y-%m-%d %H:%M UTC", time.gmtime()), "beam_rows_machine": machine(),
            "beam_rows_mem_total_gb": total / 1e9, "beam_rows_commit": _commit()}
    if not args.table:
        from sandwich.solver.jit import kernel_backend

        meta = (data or {}).get("meta") or {
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "cpus": os.cpu_count(), "mem_total_gb": total / 1e9, "machine": machine(),
            "commit": _commit(), "kernels": kernel_backend()["backend"]}
        rows = run_rows((data or {}).get("rows", []) + (data or {}).get("outside", []))
        data = {"meta": meta, "rows": [r for r in rows if r["role"] != "outside"],
                "outside": [r for r in rows if r["role"] == "outside"]}
        store.write_text(json.dumps(data, indent=1))
    constants = fit(data["rows"])
    print(json.dumps(constants, indent=1))
    text = table(data["rows"], data["meta"], constants, data.get("outside", []))
    (args.out / "memory_guard.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
