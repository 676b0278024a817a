"""Ahead-of-time build of the compiled kernels (run by ``make setup``; see sandwich/solver/jit.py).

Loading numba and its cached kernels costs ≈ 0.5-0.6 s per process. This script runs a short,
representative workload under numba's JIT (every beam option the scenes use: core levels 1-3 and
``auto``, both contact searches and face membranes, paper and stretch faces, a bonded scene, a
linear analysis, the row-envelope storage), reads the signatures each kernel was compiled for,
and compiles them all into one extension module with numba's AOT compiler
(``numba.pycc``): ``sandwich/solver/_kernels_aot*.so`` plus the manifest
``sandwich/solver/_kernels_aot.json`` (kernel → exported names and argument types, the source
files' digest, the machine key). A call the build does not cover runs the JIT as before.

Usage: ``python scripts/build_kernels.py [--if-stale]`` (``--if-stale``: do nothing when the
manifest matches the sources and the machine).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

os.environ["SANDWICH_KERNELS"] = "jit"  # record the JIT's signatures; never load an old build
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sandwich.solver import jit  # noqa: E402


def _workload() -> None:
    """Evaluate every kernel the shipped scenes reach, at small sizes."""
    import numpy as np

    from sandwich.beam import build_model, run
    from sandwich.beam import kernels as K
    from sandwich.beam.solve import scene_model_options
    from sandwich.scene_file import load_scene
    from sandwich.solver import envelope
    from sandwich.solver.envelope import structure as envelope_structure

    scenes = ROOT / "scenes"
    fig5 = load_scene(scenes / "paper-fig5-top-debond-40-load-top.toml")

    def with_options(scene, **options):
        return dataclasses.replace(scene, beam_model=dataclasses.replace(scene.beam_model,
                                                                         **options))

    runs = [
        with_options(fig5, elements=40),  # auto: levels 1-3, closest-point, averaged faces
        with_options(fig5, elements=40, core=1, contact_search="same-x", face_membrane="paper",
                     faces="paper"),
        with_options(load_scene(scenes / "paper-fig4-bonded-3pb.toml"), elements=30, core=2),
        with_options(load_scene(scenes / "paper-fig7-cantilever-c4.toml"), elements=30, core=1),
    ]
    for scene in runs:
        run(scene)
    linear = dataclasses.replace(runs[1], analysis=dataclasses.replace(runs[1].analysis,
                                                                       kind="linear"))
    run(linear)
    # the row-envelope storage and the blocks output of the layer kernels
    model = build_model(fig5, elements=30, core_level=2, **scene_model_options(fig5))
    Kt = model.tangent(np.full(model.size, 1e-3))
    saved = envelope_structure.COLUMN_ADVANTAGE  # read there when a structure is built
    envelope_structure.COLUMN_ADVANTAGE = 0.0
    try:
        envelope.factorize_envelope(Kt).solve(np.ones((model.size, 2)))
        envelope.factorize_envelope(Kt).solve(np.ones(model.size))
    finally:
        envelope_structure.COLUMN_ADVANTAGE = saved
    # a widening (contact pairs that come into contact along a path): a structure of the
    # tangent's values with its couplings beyond 5 columns stored as zeros, then the tangent
    # itself, whose values spill out of that envelope (envelope.patterns.pattern_union)
    B = Kt.tocsr(copy=True)
    far = np.abs(B.indices - np.repeat(np.arange(B.shape[0]), np.diff(B.indptr))) > 5
    B.data[far] = 0.0
    narrow = envelope.EnvelopeStructure.of(B, numeric=True)
    widened = envelope.factorize_envelope(Kt, narrow)
    if getattr(widened, "structure", narrow) is narrow:
        raise RuntimeError("build workload: the widening case did not widen")
    u_full = model.expand(np.full(model.size, 1e-3))
    for op, _, els, dofs in model.element_families():
        K.layer_blocks(op, u_full[dofs], model.mesh.lengths[els], model.width)


def _spec(t) -> list | None:
    """The manifest's description of one numba argument type (None: not exportable)."""
    from numba.core import types

    if isinstance(t, types.Array):
        return ["array", str(t.dtype), t.ndim, t.layout, bool(t.mutable)]
    if t == types.float64:
        return ["float"]
    if t == types.int64:
        return ["int"]
    if t == types.boolean:
        return ["bool"]
    return None


def _wrapper(kernel: jit.Kernel, nargs: int):
    """A plain function calling the kernel's dispatcher: exported, it is compiled with pycc's
    flags, while the dispatcher it calls keeps the kernel's own (fastmath, error model)."""
    names = ", ".join(f"a{i}" for i in range(nargs))
    env = {"f": kernel.jit}
    exec(f"def w({names}):\n    return f({names})\n", env)  # noqa: S102
    return env["w"]


def _host_features() -> None:
    """Compile for the host's instruction-set features, as numba's JIT does.

    numba's AOT code generator takes the host CPU's *name* and no feature list, so the ISA is
    whatever LLVM knows of that name; a CPU newer than numba's LLVM (AMD EPYC Zen 4 under LLVM
    14: name ``generic``) gets baseline x86-64, SSE2 only — the factorisation's rank-8 update
    ran 1.5× slower than under the JIT there. The JIT passes the host's features explicitly
    (``+avx2,+fma,+avx512f,…``); so does the build with this. The build is used only on a CPU
    with the same name and flags (:func:`sandwich.solver.jit.machine_key`).
    """
    from numba.core import codegen

    if hasattr(codegen.CPUCodegen, "_get_host_cpu_features"):  # numba 0.60 (pinned)
        codegen.AOTCPUCodegen._customize_tm_features = (
            lambda self: self._get_host_cpu_features())


def build(out_dir: Path) -> dict:
    """Run the workload, compile the AOT module into ``out_dir``; return the manifest."""
    from numba.pycc import CC

    t0 = time.perf_counter()
    _workload()
    t1 = time.perf_counter()
    cc = CC(jit.AOT_MODULE.rsplit(".", 1)[1])
    cc.output_dir = str(out_dir)
    cc.target_cpu = "host"  # the JIT's target: the same machine code (checked bit for bit)
    _host_features()
    cc.verbose = False
    exports: dict[str, list] = {}
    files: set[str] = set()
    count = 0
    for k in jit.kernels():
        files.add(str(Path(sys.modules[k.py_func.__module__].__file__).resolve()
                      .relative_to(jit.ROOT)))
        if k._jit is None:
            continue
        for sig in k._jit.nopython_signatures:
            spec = [_spec(t) for t in sig.args]
            if any(s is None for s in spec):
                continue
            name = f"k{count}"
            count += 1
            cc.export(name, sig.return_type(*sig.args))(_wrapper(k, len(sig.args)))
            exports.setdefault(k.key, []).append([name, spec])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numba.pycc's deprecation notice
        cc.compile()
    files_sorted = sorted(files)
    import numba

    manifest = {"machine": jit.machine_key(), "files": files_sorted,
                "sources": jit.source_digest(files_sorted), "numba": numba.__version__,
                "exports": exports}
    print(f"build_kernels: {count} signatures of {len(exports)} kernels "
          f"(workload {t1 - t0:.1f} s, AOT compile {time.perf_counter() - t1:.1f} s)")
    return manifest


def stale() -> bool:
    """Whether the current build is missing or does not match the sources and the machine."""
    try:
        manifest = json.loads(jit.AOT_MANIFEST.read_text())
        import numba

        return bool(jit.manifest_mismatch(manifest) or manifest["numba"] != numba.__version__
                    or not any(jit.AOT_MANIFEST.parent.glob("_kernels_aot*.so")))
    except (OSError, ValueError, KeyError):
        return True


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--if-stale", action="store_true", help="skip when the build is current")
    args = ap.parse_args()
    if args.if_stale and not stale():
        return 0
    target = jit.AOT_MANIFEST.parent
    jit.AOT_MANIFEST.unlink(missing_ok=True)  # no manifest: no build in use while this runs
    with tempfile.TemporaryDirectory(dir=target) as tmp:
        manifest = build(Path(tmp))
        for so in target.glob("_kernels_aot*.so"):
            so.unlink()
        for so in Path(tmp).glob("_kernels_aot*.so"):
            os.replace(so, target / so.name)
    tmp_manifest = jit.AOT_MANIFEST.with_suffix(".json.tmp")
    tmp_manifest.write_text(json.dumps(manifest, indent=1))
    os.replace(tmp_manifest, jit.AOT_MANIFEST)
    return 0


if __name__ == "__main__":
    sys.exit(main())
