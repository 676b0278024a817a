"""Write the corpus of valid-but-unusual scenes (tests/scenes/unusual/*.toml).

Each scene is valid by the scene format and unusual in one way a user may try: many probes,
many loads, extreme but allowed values, every support type at every end, every control. Run
``python tests/scenes/make_unusual.py`` to rewrite the folder after changing this list; the
files are committed, the test reads them (tests/test_unusual_scenes.py).
"""

from pathlib import Path

OUT = Path(__file__).resolve().parent / "unusual"
FACE = 'E = 27420.0\nnu = 0.3\n'
CORE = 'Ex = 52.5\nEz = 52.5\nGzx = 21.0\nnu_zx = 0.25\n'


def scene(name, *, length=300.0, width=60.0, t_top=0.5, t_core=25.0, t_bottom=0.5,
          face=FACE, core=CORE, supports=None, loads=None, debonds=(), probes=None,
          analysis=None, extra=""):
    supports = supports if supports is not None else [(0, "bottom", "pin"),
                                                       (length, "bottom", "roller")]
    loads = loads if loads is not None else [("top", length / 2, 10, -1)]
    probes = probes if probes is not None else [("w_top_mid", "top", length / 2)]
    analysis = analysis or ('kind = "nonlinear"\ncontrol = "load"\n'
                            'until = { load_factor = 200 }\nmax_steps = 6\n')
    out = [f'name = "{name}"', f'description = "unusual-input corpus: {name}"', "",
           "[beam]", f"length = {length!r}", f"width = {width!r}", "", "[layers]",
           f'top = {{ thickness = {t_top!r}, material = "face" }}',
           f'core = {{ thickness = {t_core!r}, material = "core" }}',
           f'bottom = {{ thickness = {t_bottom!r}, material = "face" }}', "",
           "[materials.face]", face, "[materials.core]", core]
    for x, on, kind in supports:
        out += ["[[supports]]", f"x = {float(x)!r}", f'on = "{on}"', f'type = "{kind}"', ""]
    for on, x, w, f in loads:
        out += ["[[loads]]", f'on = "{on}"', f"x = {float(x)!r}", f"width = {float(w)!r}",
                f"force = {float(f)!r}", ""]
    for iface, a, b in debonds:
        out += ["[[debonds]]", f'interface = "{iface}"', f"start = {float(a)!r}",
                f"end = {float(b)!r}", ""]
    for n, on, x in probes:
        out += ["[[probes]]", f'name = "{n}"', f'on = "{on}"', f"x = {float(x)!r}", ""]
    out += ["[analysis]", analysis, "[reference2d]", 'level = "coarse"', extra]
    return "\n".join(out)


def corpus():
    L = 300.0
    lin = 'kind = "linear"\ncontrol = "load"\nuntil = { load_factor = 100 }\n'
    s = {}
    s["many-probes-top-every-mm"] = scene("many-probes-top-every-mm", probes=[
        (f"w_top_{i:03d}", "top", float(i)) for i in range(0, 301)], analysis=lin)
    s["many-probes-both-faces"] = scene("many-probes-both-faces", probes=[
        (f"w_{on}_{i:03d}", on, 3.7 * i) for on in ("top", "bottom") for i in range(0, 81)],
        debonds=[("top", 130, 170)], analysis=lin)
    s["probe-inside-debond-off-grid"] = scene("probe-inside-debond-off-grid", probes=[
        ("w_a", "top", 131.37), ("w_b", "bottom", 168.91), ("w_c", "top", 0.013)],
        debonds=[("top", 130, 170)])
    s["many-point-loads"] = scene("many-point-loads", loads=[
        ("top", 10.0 + 14.0 * i, 0.0, -0.05) for i in range(20)])
    s["many-patch-loads-both-faces"] = scene("many-patch-loads-both-faces", loads=[
        (on, 20.0 + 26.0 * i, 6.0, -0.1) for on in ("top", "bottom") for i in range(10)])
    s["load-on-bottom-face-upward"] = scene("load-on-bottom-face-upward",
                                            loads=[("bottom", 150, 10, 1)])
    s["load-at-the-very-end"] = scene("load-at-the-very-end", supports=[(0, "faces", "clamp")],
                                      loads=[("top", 300.0, 0.0, -1)],
                                      probes=[("w_tip", "top", 300.0)])
    s["load-over-the-whole-span"] = scene("load-over-the-whole-span",
                                          loads=[("top", 150.0, 300.0, -10)])
    for left in ("pin", "roller", "clamp"):
        for right in ("pin", "roller", "clamp"):
            if (left, right) == ("roller", "roller"):
                continue  # a mechanism along x: refused by design, not an unusual valid input
            for on in (("faces",) if "clamp" in (left, right) else ("bottom", "top")):
                n = f"supports-{left}-{right}-{on}"
                s[n] = scene(n, supports=[(0, on, left), (L, on, right)], analysis=lin)
    s["cantilever-bottom-clamp-only"] = scene("cantilever-bottom-clamp-only",
                                              supports=[(0, "bottom", "clamp")],
                                              loads=[("top", 290, 10, -1)],
                                              probes=[("w_tip", "top", 300.0)], analysis=lin)
    s["supports-inside-the-span"] = scene(
        "supports-inside-the-span", supports=[(50, "bottom", "pin"), (250, "bottom", "roller")])
    s["tiny-beam"] = scene("tiny-beam", length=20.0, width=5.0, t_top=0.2, t_core=2.0,
                           t_bottom=0.2, probes=[("w_mid", "top", 10.0)],
                           loads=[("top", 10.0, 1.0, -0.01)], analysis=lin)
    s["long-slender-beam"] = scene("long-slender-beam", length=3000.0,
                                   probes=[("w_mid", "top", 1500.0)],
                                   loads=[("top", 1500.0, 10.0, -0.1)], analysis=lin)
    s["very-soft-core"] = scene("very-soft-core", core='Ex = 0.05\nEz = 0.05\nGzx = 0.02\n'
                                'nu_zx = 0.25\n', analysis=lin)
    s["very-stiff-core"] = scene("very-stiff-core", core='Ex = 5000.0\nEz = 5000.0\n'
                                 'Gzx = 2000.0\nnu_zx = 0.25\n', analysis=lin)
    s["orthotropic-core-and-thick-faces"] = scene(
        "orthotropic-core-and-thick-faces", t_top=3.0, t_bottom=1.0,
        core='Ex = 10.0\nEz = 120.0\nGzx = 15.0\nnu_zx = 0.05\n', analysis=lin)
    s["unequal-faces-thin-top"] = scene("unequal-faces-thin-top", t_top=0.1, t_bottom=2.0,
                                        debonds=[("top", 100, 200)])
    s["debond-at-the-left-end"] = scene("debond-at-the-left-end", debonds=[("bottom", 0, 40)],
                                        supports=[(0, "faces", "clamp")],
                                        loads=[("top", 295, 10, -1)],
                                        probes=[("w_tip", "top", 300.0)])
    s["debond-at-the-right-end"] = scene("debond-at-the-right-end", debonds=[("top", 260, 300)])
    s["debonds-both-interfaces-overlapping"] = scene(
        "debonds-both-interfaces-overlapping", debonds=[("top", 100, 180), ("bottom", 120, 200)])
    s["many-short-debonds"] = scene("many-short-debonds", debonds=[
        ("top" if i % 2 else "bottom", 20.0 + 25.0 * i, 30.0 + 25.0 * i) for i in range(10)])
    s["debond-nearly-the-whole-span"] = scene("debond-nearly-the-whole-span",
                                              debonds=[("top", 5, 295)], analysis=lin)
    s["tiny-debond"] = scene("tiny-debond", debonds=[("top", 149.9, 150.1)])
    s["displacement-control"] = scene(
        "displacement-control", debonds=[("top", 130, 170)],
        analysis='kind = "nonlinear"\ncontrol = "displacement"\n'
                 'until = { probe = "w_top_mid", value = -2 }\nmax_steps = 8\n')
    s["arc-length-upward-target"] = scene(
        "arc-length-upward-target", loads=[("bottom", 150, 10, 1)],
        probes=[("w_bot", "bottom", 150.0)],
        analysis='kind = "nonlinear"\ncontrol = "arc-length"\n'
                 'until = { probe = "w_bot", value = 1 }\nmax_steps = 8\n')
    s["huge-load-linear"] = scene("huge-load-linear", loads=[("top", 150, 10, -1e6)],
                                  analysis=lin)
    s["tiny-load-nonlinear"] = scene("tiny-load-nonlinear", loads=[("top", 150, 10, -1e-6)])
    s["one-step-budget"] = scene("one-step-budget", analysis='kind = "nonlinear"\n'
                                 'control = "load"\nuntil = { load_factor = 500 }\n'
                                 'max_steps = 1\n')
    s["beam-options-uniform-level-2"] = scene(
        "beam-options-uniform-level-2", debonds=[("top", 130, 170)],
        extra='\n[beam_model]\ncore = 2\nelements = 30\ngrading = "uniform"\n')
    return s


if __name__ == "__main__":
    OUT.mkdir(exist_ok=True)
    for old in OUT.glob("*.toml"):
        old.unlink()
    for name, text in corpus().items():
        (OUT / f"{name}.toml").write_text(text)
    print(f"{len(corpus())} scenes in {OUT}")
