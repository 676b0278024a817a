"""The kernels' ahead-of-time build (sandwich/solver/jit.py, scripts/build_kernels.py).

The AOT functions do not check their arguments, so the matcher is tested to refuse every type
but the exported one; a stale or foreign build must not be used; and where the build is present
(``make setup`` made it) its results must equal numba's JIT bit for bit, on the model's force,
tangent, factorisation and a whole path, without importing numba.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from sandwich.solver import jit

ROOT = Path(__file__).resolve().parents[2]
BUILT = jit.kernel_backend()["backend"] == "aot"
needs_build = pytest.mark.skipif(not BUILT, reason=f"no AOT build: {jit.kernel_backend()}")


def test_matcher_accepts_only_the_exported_types():
    spec = [["array", "float64", 2, "C", True], ["array", "int32", 1, "A", False], ["float"],
            ["int"], ["bool"]]
    m = jit.argument_matcher(spec)
    a, i = np.zeros((3, 2)), np.arange(4, dtype=np.int32)
    assert m((a, i, 1.0, 2, True))
    assert m((a, i[::2], np.float64(1.0), np.int64(2), np.bool_(False)))  # layout "A": any
    ro = a.copy()
    ro.flags.writeable = False
    for bad in [(a.astype(np.float32), i, 1.0, 2, True),  # dtype
                (a[:, :1], i, 1.0, 2, True),  # not C-contiguous
                (a.T, i, 1.0, 2, True),
                (a.ravel(), i, 1.0, 2, True),  # ndim
                (ro, i, 1.0, 2, True),  # read-only where the kernel writes
                (a, i.astype(np.int64), 1.0, 2, True),
                (a, i, 1, 2, True),  # a Python int where a float64 is exported
                (a, i, 1.0, 2.0, True),
                (a, i, 1.0, True, True),  # bool is not an int64 here
                (a, i, 1.0, 2, 1),
                (a, i, 1.0, 2),  # count
                (list(a), i, 1.0, 2, True)]:
        assert not m(bad), bad


def _manifest_at(tmp_path, monkeypatch, **changes):
    manifest = {"machine": jit.machine_key(), "files": ["sandwich/solver/jit.py"],
                "sources": jit.source_digest(["sandwich/solver/jit.py"]), "exports": {}}
    manifest.update(changes)
    path = tmp_path / "_kernels_aot.json"
    path.write_text(json.dumps(manifest))
    monkeypatch.setattr(jit, "AOT_MANIFEST", path)
    monkeypatch.setattr(jit, "AOT_MODULE", "sandwich.solver._no_such_module")
    jit.aot_exports.cache_clear()


@pytest.mark.parametrize("changes, reason", [
    ({"sources": "0" * 64}, "source changed"),
    ({"machine": {**jit.machine_key(), "cpu": "another"}}, "another machine"),
    ({"machine": {**jit.machine_key(), "numpy": "0.0"}}, "another machine"),
    ({}, "did not load"),  # current manifest, but the module is missing
])
def test_a_stale_foreign_or_broken_build_is_not_used(tmp_path, monkeypatch, changes, reason):
    monkeypatch.delenv("SANDWICH_KERNELS", raising=False)
    try:
        _manifest_at(tmp_path, monkeypatch, **changes)
        assert jit.aot_exports() == {}
        assert jit.kernel_backend()["backend"] == "jit"
        assert reason in jit.kernel_backend()["reason"]
    finally:
        monkeypatch.undo()
        jit.aot_exports.cache_clear()


def test_no_build_is_used_where_the_cpu_cannot_be_identified(tmp_path, monkeypatch):
    """A build made and checked without /proc/cpuinfo would match any CPU: refused."""
    monkeypatch.delenv("SANDWICH_KERNELS", raising=False)
    real = jit.machine_key
    try:
        monkeypatch.setattr(jit, "machine_key", lambda: {**real(), "cpu": ""})
        _manifest_at(tmp_path, monkeypatch)  # a manifest matching that key exactly
        assert jit.aot_exports() == {}
        assert "cannot be identified" in jit.kernel_backend()["reason"]
    finally:
        monkeypatch.undo()
        jit.aot_exports.cache_clear()


def test_missing_build_and_the_jit_switch(tmp_path, monkeypatch):
    try:
        monkeypatch.setattr(jit, "AOT_MANIFEST", tmp_path / "none.json")
        jit.aot_exports.cache_clear()
        assert jit.aot_exports() == {} and "no ahead-of-time build" in jit.kernel_backend()[
            "reason"]
        monkeypatch.setenv("SANDWICH_KERNELS", "jit")
        jit.aot_exports.cache_clear()
        assert jit.aot_exports() == {} and jit.kernel_backend()["reason"] == (
            "SANDWICH_KERNELS=jit")
    finally:
        monkeypatch.undo()
        jit.aot_exports.cache_clear()


_PROBE = r"""
import dataclasses, sys
import numpy as np
sys.path.insert(0, {root!r})
from sandwich.solver import jit
from sandwich.beam import build_model, run
from sandwich.beam.solve import scene_model_options
from sandwich.scene_file import load_scene
scene = load_scene({scene!r})
out = {{}}
for level in (1, 2):
    m = build_model(scene, elements=30, core_level=level, **scene_model_options(scene))
    u = np.sin(np.arange(m.size) * 0.37) * 0.05
    f = m.internal_force(u)
    K = m.tangent(u)
    fac = m.factorize(K)
    out[f"f{{level}}"], out[f"K{{level}}"] = f, K.data
    out[f"x{{level}}"] = fac.solve(np.stack([f, m.f_ref], axis=1))
    out[f"neg{{level}}"] = np.array([fac.negative_pivots])
short = dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model, elements=40,
                                                                  core=1))
r = run(short)
out["path"] = np.array([[s.load_factor, *s.probes.values()] for s in r.states])
np.savez({out_file!r}, **out)
print(jit.kernel_backend()["backend"], "numba" in sys.modules)
"""


def _probe(tmp_path, mode):
    out_file = tmp_path / f"{mode}.npz"
    code = _PROBE.format(root=str(ROOT), out_file=str(out_file),
                         scene=str(ROOT / "scenes" / "paper-fig5-top-debond-40-load-top.toml"))
    env = dict(os.environ)
    env.pop("SANDWICH_KERNELS", None)
    if mode == "jit":
        env["SANDWICH_KERNELS"] = "jit"
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=600, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    return p.stdout.split(), np.load(out_file)


@needs_build
def test_aot_build_equals_the_jit_bit_for_bit_without_importing_numba(tmp_path):
    """fig. 5 at core levels 1 and 2 (packed and sum-factorised kernels, averaged faces,
    closest-point contact, envelope LDLᵀ and paired solves) and a whole path at level 1."""
    said_aot, aot = _probe(tmp_path, "aot")
    said_jit, ref = _probe(tmp_path, "jit")
    assert said_aot == ["aot", "False"]  # the build covered every call: numba never imported
    assert said_jit == ["jit", "True"]
    assert sorted(aot.files) == sorted(ref.files)
    for name in ref.files:
        # Bit for bit: the build compiles for the host's features as the JIT does
        # (scripts/build_kernels.py, _host_features). Without them, on a CPU newer than numba's
        # LLVM (AMD EPYC, 2026-12-04), the build was baseline x86-64 and differed at round-off.
        assert aot[name].shape == ref[name].shape, name
        assert np.array_equal(aot[name], ref[name]), name
    assert ref["path"].shape[0] > 5 and np.all(np.isfinite(ref["path"]))


@needs_build
def test_a_call_the_build_does_not_cover_runs_the_jit():
    """float32 values and a strided vector: no exported signature; the JIT gives the answer."""
    from sandwich.beam import kernels

    rng = np.random.default_rng(0)
    A = (rng.standard_normal((6, 6)) > 0.5) * rng.standard_normal((6, 6))
    import scipy.sparse as sp

    K = sp.csr_matrix(A)
    x = rng.standard_normal(12)
    want = np.abs(A) @ np.abs(x[::2])
    got = kernels.abs_matvec(K.indptr, K.indices, K.data, x[::2])  # strided: not exported
    assert np.allclose(got, want, rtol=1e-14, atol=0)
    got32 = kernels.abs_matvec(K.indptr, K.indices, K.data.astype(np.float32), x[::2].copy())
    assert np.allclose(got32, np.abs(A.astype(np.float32)) @ np.abs(x[::2]), rtol=1e-6)


def test_a_malformed_export_entry_runs_the_jit(monkeypatch):
    """An entry whose types cannot be read must not stop a run (its kernel takes the JIT).

    The matchers are made on a kernel's first call, outside :func:`jit.aot_exports`'s guard.
    """
    def never(*args):
        raise AssertionError("an export with unreadable types was called")

    kernel = jit.Kernel(lambda x: 2.0 * x, False, register=False)
    assert kernel not in jit.kernels()  # not one of the project's kernels
    monkeypatch.setattr(jit, "aot_exports",
                        lambda: {kernel.key: ((["no such kind"], never),)})
    assert kernel(1.5) == 3.0


@needs_build
def test_the_build_runs_from_a_read_only_copy(tmp_path):
    """The packages copied with the build into a location nothing can be written to."""
    site = tmp_path / "site"
    for pkg in ("sandwich",):
        shutil.copytree(ROOT / pkg, site / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    for d in (site / "sandwich" / "solver", site / "sandwich" / "solver" / "envelope",
              site / "sandwich" / "beam"):
        (d / "__pycache__").write_text("not a directory")
    code = ("import sys, numpy as np, scipy.sparse as sp\n"
            "from sandwich.solver import envelope, jit\n"
            "f = envelope.factorize_envelope(sp.csr_matrix(np.diag([1.0, -2.0, 3.0])))\n"
            "print(jit.kernel_backend()['backend'], f.negative_pivots, 'numba' in sys.modules)\n")
    env = {k: v for k, v in os.environ.items() if k not in ("SANDWICH_KERNELS",
                                                             "NUMBA_CACHE_DIR")}
    env.update(PYTHONPATH=str(site), HOME=str(tmp_path / "nohome"), PYTHONDONTWRITEBYTECODE="1")
    (tmp_path / "nohome").write_text("not a directory")
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=300, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == ["aot", "1", "False"]
