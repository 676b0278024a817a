"""Peak memory of the ``sandwich`` commands against the guard's estimate (sandwich.models.memory).

Every row runs the real command line (``python -m sandwich.cli solve|mesh ... --quiet``) on a
variant of ``scenes/default.toml`` in its own process and reads that process's peak resident set
size from ``os.wait4`` (``ru_maxrss``, the kernel's high-water mark of the whole process), read
by a small launcher process (:data:`LAUNCHER`). The
beam rows follow a short path (until w_top_mid = UNTIL mm) at a given element count and core
level; the 2D rows mesh only (``sandwich mesh``) or solve ``max_steps = 2`` steps at a mesh level
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
BEAM_ROWS = [  # (role, elements, core)
    ("fit", 2000, "1"), ("fit", 4000, "1"), ("fit", 8000, "1"),
    ("fit", 2000, "3"), ("fit", 4000, "3"), ("fit", 8000, "3"),
    ("check", 2000, "5"), ("check", 1000, "4"), ("check", 4000, "auto"),
]
TWO_D_ROWS = [  # (role, command, level, refine)
    ("fit", "mesh", "coarse", 0), ("fit", "mesh", "medium", 0), ("fit", "mesh", "coarse", 1),
    ("fit", "mesh", "coarse", 2), ("fit", "mesh", "fine", 1), ("check", "mesh", "coarse", 3),
    ("check", "mesh", "coarse", 6),
    ("fit", "solve", "coarse", 0), ("fit", "solve", "medium", 0), ("fit", "solve", "coarse", 1),
    ("fit", "solve", "coarse", 2), ("fit", "solve", "fine", 0), ("check", "solve", "coarse", 3),
]


def beam_scene(elements: int, core: str) -> str:
    """The default scene, a short path, ``[beam_model]`` at ``elements`` and ``core``."""
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = text.replace("value = -8", f"value = {UNTIL}")
    core_value = '"auto"' if core == "auto" else core
    return text + f"\n[beam_model]\nelements = {elements}\ncore = {core_value}\n"


def two_d_scene(level: str, refine: int, steps: int) -> str:
    """The default scene with ``[reference2d]`` at ``level`` + ``refine``, ``steps`` steps."""
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = text.replace('level = "coarse"', f'level = "{level}"\nrefine = {refine}')
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
        return ("beam", row["elements"], row["core"])
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
        for role, elements, core in BEAM_ROWS:
            if ("beam", elements, core) not in done:
                d = base / f"beam-{elements}-{core}"
                d.mkdir()
                (d / "s.toml").write_text(beam_scene(elements, core))
                r = measure([*py, "solve", "s.toml", "--model", "beam", "--out", "out",
                             "--quiet"], d)
                info = _solve_info(d)
                done[("beam", elements, core)] = {
                    "kind": "beam", "elements": elements, "core": core,
                    "steps": info.get("steps"), "dofs": info.get("dofs"), **r}
                print("beam", elements, core, r["peak_rss_bytes"] / 2**20, r["wall_s"],
                      flush=True)
            rows.append({**done[("beam", elements, core)], "role": role})
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

    text = (beam_scene(row["elements"], row["core"]) if row["kind"] == "beam"
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

    Each row's kept states (8 bytes a DOF each, at the steps it took) are taken off first.
    """
    import numpy as np

    from sandwich.models import memory

    def solve(kind, feature):
        A, y = [], []
        for r in rows:
            if r["kind"] == kind and r["role"] == "fit":
                scene = scene_of(r)
                states = (r["steps"] or 0) + 1 if kind != "2d-mesh" else 0
                kept = 0.0
                if kind != "2d-mesh":
                    # the states term alone: the estimate with the other constants at zero
                    kept = memory.states_bytes(scene, "beam" if kind == "beam" else "2d", states)
                A.append([1.0, feature(scene)])
                y.append(r["peak_rss_bytes"] - kept)
        A, y = np.array(A), np.array(y)
        return np.linalg.lstsq(A / y[:, None], np.ones_like(y), rcond=None)[0]

    b0, w = solve("beam", memory.beam_work)
    t0, c = solve("2d-solve", lambda s: memory.n_log_n(2 * memory.mesh_size(s)[1]))
    m0, m = solve("2d-mesh", lambda s: memory.mesh_size(s)[0])
    return {"BEAM_BASE": b0, "BEAM_PER_WORK": w, "TWO_D_BASE": t0, "TWO_D_PER_DOF": c,
            "MESH_BASE": m0, "MESH_PER_CELL": m}


def table(rows: list[dict], meta: dict, constants: dict[str, float]) -> str:
    """Markdown table: measured peak RSS next to the estimate."""
    from sandwich.models import memory

    mib = 2**20
    now = {k: getattr(memory, k) for k in constants}
    lines = ["# Peak memory of the command line against the guard's estimate", "",
             f"Measured on {meta.get('machine', 'an unnamed machine')}, {meta['date']}."
             + (f" Beam and import rows measured again on {meta['beam_rows_machine']}, "
                f"{meta['beam_rows_again']}." if "beam_rows_machine" in meta else ""), "",
             f"Measured {meta['date']}"
             + (f" (the beam rows and the import row again {meta['beam_rows_again']}, with the "
                "kernels of the ahead-of-time build: no numba in the process)"
                if "beam_rows_again" in meta else "")
             + f" by `benchmarks/memory_guard.py` on a {meta['cpus']}-CPU "
             f"machine (MemTotal {meta['mem_total_gb']:.1f} GB, shared with another job: load "
             "in the last column); peak RSS = `ru_maxrss` of the command's process "
             f"(`os.wait4`). Scene: `scenes/default.toml`; beam rows to w_top_mid = {UNTIL} mm, "
             "2D solve rows 2 steps (`max_steps = 2`).", "",
             "Estimate (`sandwich.models.memory`) at the states the run kept (the fit) and as "
             "the guard "
             "judges it, with every step of the scene's budget kept (`max_steps = 400` for the "
             "beam rows). Role *fit*: the row set the constants; *check*: predicted, not fitted.",
             "",
             "| command | resolution | role | steps | DOFs | peak RSS (MiB) | estimate (MiB) | "
             "estimate / measured | guard's estimate (MiB) | wall (s) | load before/after |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        rss = r["peak_rss_bytes"] / mib
        load = f"{r['load_before']:.2f}/{r['load_after']:.2f}"
        if r["kind"] == "import":
            lines.append(f"| validate | (imports only) | | | | {rss:.0f} | | | | "
                         f"{r['wall_s']:.1f} | {load} |")
            continue
        if r["kind"] == "beam":
            what, res = "solve beam", f"{r['elements']} elements, core {r['core']}"
        else:
            what = "mesh" if r["kind"] == "2d-mesh" else "solve 2d"
            res = f"{r['level']} + refine {r['refine']}"
        kept = (r["steps"] or 0) + 1 if r["kind"] != "2d-mesh" else None
        est, guard = estimate_of(r, kept), estimate_of(r)
        lines.append(
            f"| {what} | {res} | {r['role']} | {r.get('steps') or ''} | {r.get('dofs') or ''} "
            f"| {rss:.0f} | {est / mib:.0f} | {est / r['peak_rss_bytes']:.2f} | "
            f"{guard / mib:.0f} | {r['wall_s']:.1f} | {load} |")
    lines += ["", "Constants fitted to the *fit* rows (in `sandwich/models/memory.py`: "
              + ", ".join(f"`{k}` = {v:.4g}" + ("" if math.isclose(v, now[k], rel_tol=0.01)
                                                 else f" (module: {now[k]:.4g})")
                          for k, v in constants.items()) + ")."]
    bad = [r for r in rows if r["exit"] not in (0, 1)]
    if bad:
        lines += ["", "Rows that failed: " + ", ".join(f"{r['kind']} exit {r['exit']}"
                                                       for r in bad)]
    return "\n".join(lines) + "\n"


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
    if data is not None and args.again_beam:
        data["rows"] = [r for r in data["rows"] if r["kind"] not in ("beam", "import")]
        data["meta"] = {**data["meta"], "beam_rows_again": time.strftime(
            "%Y-%m-%d %H:%M UTC", time.gmtime()), "beam_rows_machine": machine()}
    if not args.table:
        mem = Path("/proc/meminfo").read_text()
        total = int(re.search(r"MemTotal:\s+(\d+)", mem).group(1)) * 1024
        meta = (data or {}).get("meta") or {
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "cpus": os.cpu_count(), "mem_total_gb": total / 1e9, "machine": machine()}
        data = {"meta": meta, "rows": run_rows((data or {}).get("rows", []))}
        store.write_text(json.dumps(data, indent=1))
    constants = fit(data["rows"])
    print(json.dumps(constants, indent=1))
    text = table(data["rows"], data["meta"], constants)
    (args.out / "memory_guard.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
