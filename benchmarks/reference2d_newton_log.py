"""Newton iteration log of the 2D reference on fig5 with contact active.

fig5 (three-point bending, top debond 130-170, patch load on the top face at mid-span) is
followed by the production path solver to w_top_mid = UNTIL mm at level coarse. From the last
converged state (u_n, λ_n), where the lip is pressed shut under the load and open near the crack
tips, one more load step λ_n → λ_n + Δλ (Δλ = the path's last load increment, unless
--dlam-factor scales it) is solved by full Newton at fixed load, from the tangent (Euler)
predictor u_n + Δλ K(u_n)⁻¹ f_ref, without line search, down to round-off (the loop stops when
the residual stops decreasing or at --max-iterations). Logged per iteration: ‖R‖ (N), ‖R‖ over
‖λ f_ref‖, ‖δu‖, active lip nodes (gap < 0) and how many changed status since the previous
iterate, the ratio ‖R_{k+1}‖/‖R_k‖² (bounded for quadratic convergence) and the observed order
log(r_{k+1}/r_k)/log(r_k/r_{k-1}).

Writes benchmarks/results/reference2d/newton_log.{md,json} (or into ``--out DIR``; a rerun
replaces them). From the project root:

    python -m benchmarks.reference2d_newton_log [--until -5] [--out DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os

import numpy as np

from benchmarks.provenance import RESULTS, ROOT, add_out_argument, measured_on
from sandwich.scene_file import load_scene

OUT = RESULTS / "reference2d"
SCENE = "paper-fig5-top-debond-40-load-top"


def active_set(system) -> tuple[np.ndarray, np.ndarray]:
    """Active flags and gaps of every slave (all pairs) at the system's current state."""
    flags, gaps = [], []
    for state in system.last_contact:
        f = np.zeros(len(state.gap), dtype=bool)
        f[state.active] = True
        flags.append(f)
        gaps.append(state.gap)
    return np.concatenate(flags), np.concatenate(gaps)


def slave_x(system) -> np.ndarray:
    """Reference x of every slave (all pairs, in the order of :func:`active_set`)."""
    return np.concatenate([p.x_ref for p in system.contacts])


def newton_log(system, u_n: np.ndarray, lam: float, dlam: float, max_iterations: int,
               floor: float, predictor: bool = True) -> list[dict]:
    """Full Newton at λ = lam + dlam from u_n (+ tangent predictor); one dict per iterate.

    Stops after ``max_iterations`` corrections, or once ‖R‖ ≤ ``floor`` (N, the round-off level)
    and no longer halves.
    """
    f_ref = system.f_ref
    target = lam + dlam
    u = u_n.copy()
    if predictor:
        u = u + dlam * system.factorize(system.tangent(u_n)).solve(f_ref)
    scale = system.norm(target * f_ref)
    rows, prev_flags, du_norm = [], None, math.nan
    xs = slave_x(system)
    for it in range(max_iterations + 1):
        r = system.internal_force(u) - target * f_ref
        system.commit(u, target)  # (stores the contact state of u; penalty contact: no history)
        flags, gaps = active_set(system)
        changed = int(np.sum(flags != prev_flags)) if prev_flags is not None else None
        changed_x = ([f"{x:g}{'+' if a else '-'}" for x, a in
                      zip(xs[flags != prev_flags], flags[flags != prev_flags], strict=True)]
                     if prev_flags is not None else [])
        prev_flags = flags
        norm = system.norm(r)
        inactive_near = np.abs(gaps[~flags]) if np.any(~flags) else np.array([np.inf])
        rows.append({"iteration": it, "residual": norm, "relative": norm / scale,
                     "du": du_norm, "active": int(flags.sum()), "changed": changed,
                     "changed_at_x": changed_x,
                     "smallest_active_penetration": float(np.min(-gaps[flags]))
                     if flags.any() else None,
                     "smallest_open_gap": float(inactive_near.min())})
        if it == max_iterations or not math.isfinite(norm):
            break
        if norm <= floor and len(rows) >= 2 and norm >= 0.5 * rows[-2]["residual"]:
            break  # round-off floor reached: no more decrease
        du = system.factorize(system.tangent(u)).solve(r)
        du_norm = system.norm(du)
        u = u - du
    for k, row in enumerate(rows):
        r0 = rows[k - 1]["residual"] if k >= 1 else math.nan
        rm = rows[k - 2]["residual"] if k >= 2 else math.nan
        row["ratio_to_square"] = row["residual"] / r0 ** 2 if k >= 1 else math.nan
        row["order"] = (math.log(row["residual"] / r0) / math.log(r0 / rm)
                        if k >= 2 and r0 != rm and row["residual"] > 0 else math.nan)
    return rows


def fmt(x, spec):
    return "" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def md_table(rows: list[dict]) -> list[str]:
    out = ["| it | ‖R‖ (N) | ‖R‖/‖λ f_ref‖ | ‖δu‖ before (mm) | active lip nodes | changed "
           "(x in mm: + closed, − opened) | ‖R_k‖/‖R_k-1‖² (1/N) | order |", "|" + "---|" * 8]
    for r in rows:
        where = " ".join(r["changed_at_x"][:6]) + (" …" if len(r["changed_at_x"]) > 6 else "")
        out.append(f"| {r['iteration']} | {r['residual']:.3e} | {r['relative']:.2e} | "
                   f"{fmt(r['du'], '.2e')} | {r['active']} | {fmt(r['changed'], 'd')} "
                   f"{'(' + where + ')' if where else ''} | "
                   f"{fmt(r['ratio_to_square'], '.2e')} | {fmt(r['order'], '.2f')} |")
    return out


def main():
    """Follow the path to the start state, run the fixed-load Newton logs, write them."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--until", type=float, default=-5.0, help="w_top_mid of the start state (mm)")
    p.add_argument("--level", default="coarse")
    p.add_argument("--dlam-factor", type=float, nargs="+", default=[0.25, 1.0, 4.0],
                   help="step sizes as multiples of the path's last load increment")
    p.add_argument("--max-iterations", type=int, default=15)
    add_out_argument(p, OUT)
    args = p.parse_args()
    stamp = measured_on()
    from sandwich.plane2d import solve  # FEniCSx: imported when the log is run

    scene = load_scene(ROOT / "scenes" / f"{SCENE}.toml")
    scene = dataclasses.replace(scene, analysis=dataclasses.replace(
        scene.analysis, until_value=args.until))
    sol = solve(scene, level=args.level, keep_states=True, estimate=False)
    model, states = sol.reference2d_states
    system = model.system
    assert sol.converged, sol.message
    (_, lam_prev, _), (step_n, lam_n, u_n) = states[-2], states[-1]
    system.commit(u_n, lam_n)
    flags, gaps = active_set(system)
    path_its = [r.iterations for r in sol.history[1:]]
    head = {
        "scene": SCENE, "level": args.level, "dofs": sol.dofs, "start_step": step_n,
        "start_load_factor": lam_n, "start_w_top_mid": sol.history[-1].probes["w_top_mid"],
        "slaves": int(len(flags)), "active_at_start": int(flags.sum()),
        "newton_tol_of_path": sol.extra["newton_tol"],
        "residual_roundoff_bound": sol.extra["residual_roundoff_bound"],
        "contact_penalty": sol.extra["contact_penalty"], "path_iterations": path_its,
        "path_load_increment": lam_n - lam_prev, "loadavg": os.getloadavg(),
        "measured": stamp,
    }
    # round-off level of the residual: the a-priori bound (relative) times the load
    floor = head["residual_roundoff_bound"] * system.norm(lam_n * system.f_ref)
    runs = [(f"from the end state (step {step_n}), Δλ = {fac:g} × the path's last load "
             f"increment", step_n, lam_n, u_n, fac * (lam_n - lam_prev))
            for fac in args.dlam_factor]
    # the path step that needed most iterations (not the first): the same load step again
    k = 2 + int(np.argmax(path_its[1:]))
    (_, lam_a, u_a), (_, lam_b, _) = states[k - 1], states[k]
    runs.append((f"path step {k} again ({path_its[k - 1]} iterations in the path, arc-length), "
                 f"at fixed load: from step {k - 1} to its λ", k - 1, lam_a, u_a, lam_b - lam_a))
    logs = []
    for title, start, lam0, u0, dlam in runs:
        rows = newton_log(system, u0, lam0, dlam, args.max_iterations, floor)
        system.commit(u0, lam0)
        logs.append({"title": title, "start_step": start, "start_load_factor": lam0,
                     "dlam": dlam, "rows": rows})
        print(f"{title}: λ {lam0:.6g} → {lam0 + dlam:.6g}")
        print("\n".join(md_table(rows)), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "newton_log.json").write_text(json.dumps({**head, "logs": logs}, indent=2) + "\n")
    lines = [
        f"# Newton log, fig5 ({SCENE}), level {args.level}, contact active",
        "",
        f"Written by `benchmarks/reference2d_newton_log.py --until {args.until}`. "
        f"{sol.dofs} DOFs; start state: path step {step_n}, λ = {lam_n:.6g}, w_top_mid = "
        f"{head['start_w_top_mid']:.6g} mm, {head['active_at_start']} of {head['slaves']} lip "
        f"nodes in contact (penalty {head['contact_penalty']:.3g} N/mm³). Path Newton iterations "
        f"per step up to there: {path_its}; the path's Newton tolerance "
        f"{head['newton_tol_of_path']:.2g} (relative residual; the round-off bound: "
        f"{floor:.2g} N at λ_n). Full Newton at fixed load from the tangent "
        f"predictor, no line search; `changed` = lip nodes whose contact status differs from "
        f"the previous iterate.",
        "", stamp, ""]
    for log in logs:
        lam0 = log["start_load_factor"]
        lines += [f"## {log['title']}: λ = {lam0:.6g} → {lam0 + log['dlam']:.6g}", ""]
        lines += md_table(log["rows"]) + [""]
    (args.out / "newton_log.md").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
