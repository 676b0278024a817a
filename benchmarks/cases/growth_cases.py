"""Growing-debond scenes with closed-form checks, shared by the growth tests and benchmarks.

The face cantilever of :mod:`benchmarks.cases.fracture_cases` (an end force on the top face at
an open mouth at x = 0, the tip at a, faces clamped at x = L) with a toughness and growth:
beam theory with a root rotation gives G = 6 P² (a + χ t)² / (b² E t³), χ independent of a, so
the onset load of each length is λ_c = √(G_c b² E t³ / 6) / (a + χ t): 1/λ_c is linear in a
with the slope √(6 / (G_c b² E t³)) (:func:`onset_slope`), whatever χ.
"""

import dataclasses

from benchmarks.cases.fracture_cases import E_FACE, T_FACE, WIDTH, scene
from sandwich.scene import Growth, Toughness

#: N/mm, the same in both modes (the onset does not depend on the mode mix); small, so that the
#: face deflects by at most 0.14 mm at its onsets up to 80 mm (a rotation of 0.2 %) and the
#: nonlinear path is the linear response the closed form holds for
GC = 1e-5


def cantilever(step=10.0, max_length=80.0, a=40.0, gc=GC, until=0.5):
    """The face cantilever, debond [0, a], grown by ``step`` up to ``max_length`` (mm)."""
    sc = scene([("top", 0.0, 1.0)], a=a, until=until, core=1)
    d = dataclasses.replace(sc.debonds[0], toughness=Toughness(gc, gc),
                            growth=Growth(step, max_length))
    return dataclasses.replace(sc, debonds=(d,))


#: MPa: the cohesive strength of the face cantilever's interface. Its process zone, of the order
#: of E_core G_c / σ_c² = 20 mm, spans a dozen elements at the default mesh, and is a fraction
#: of the debond length (40 mm and up), where the closed form holds
SIGMA_C = 0.01


def cohesive_cantilever(a=40.0, gc=GC, sigma_c=SIGMA_C, zone=80.0, until=0.5, elements=240):
    """The face cantilever, debond [0, a], grown by a cohesive law over ``zone`` mm ahead."""
    sc = scene([("top", 0.0, 1.0)], a=a, until=until, core=1, elements=elements)
    d = dataclasses.replace(sc.debonds[0], toughness=Toughness(gc, gc),
                            growth=Growth(method="cohesive", sigma_c=sigma_c, tau_c=sigma_c,
                                          zone=zone))
    return dataclasses.replace(sc, debonds=(d,))


def propagation_load(deflection, gc=GC):
    """The face cantilever's load (N) while its debond grows at G = G_c, at the end deflection.

    Beam theory with a root rotation: C(a) = 4 (a + χ t)³ / (E b t³) and
    G = P²/(2b) dC/da = 6 P² (a + χ t)² / (b² E t³); eliminating a + χ t between G = G_c and
    δ = C P gives P = √(4 b² t^{3/2} (E G_c / 6)^{3/2} / (E δ)), whatever χ.
    """
    return (4.0 * WIDTH**2 * T_FACE**1.5 * (E_FACE * gc / 6.0) ** 1.5
            / (E_FACE * abs(deflection))) ** 0.5


def onset_slope(gc=GC):
    """d(1/λ_c)/da of the face cantilever (1/(N mm)): √(6 / (G_c b² E t³))."""
    return (6.0 / (gc * WIDTH**2 * E_FACE * T_FACE**3)) ** 0.5


def shipped(name, toughness, step=4.0, max_length=80.0, debond=0, level=None):
    """A shipped scene (``scenes/<name>.toml``) with debond ``debond`` tough and growing.

    ``toughness`` is (GIc, GIIc) in N/mm (eta 2); ``level`` sets the 2D mesh level.
    """
    from benchmarks.provenance import ROOT
    from sandwich.scene_file import load_scene

    sc = load_scene(ROOT / "scenes" / f"{name}.toml")
    d = dataclasses.replace(sc.debonds[debond], toughness=Toughness(*toughness),
                            growth=Growth(step, max_length))
    sc = dataclasses.replace(sc, debonds=tuple(d if i == debond else o
                                               for i, o in enumerate(sc.debonds)))
    if level is not None:
        sc = dataclasses.replace(sc, reference2d=dataclasses.replace(sc.reference2d,
                                                                     level=level))
    return sc


#: The growth benchmark's cases: (scene builder, what it shows). Toughnesses are chosen so that
#: each debond grows well inside its scene's load range (an interface weaker than a real foam
#: core's): fig. 5's mixed-mode tips below the face's buckling, c3's clamp debond once its face
#: has buckled away (mode I).
CASES = {
    "cantilever": (lambda level: dataclasses.replace(
        cantilever(), reference2d=dataclasses.replace(cantilever().reference2d, level=level)),
        "face cantilever, end force at the open mouth (closed form: 1/λ_c linear in a)"),
    "fig5": (lambda level: shipped("paper-fig5-top-debond-40-load-top", (0.004, 0.008),
                                   level=level),
             "fig. 5, 40 mm top debond under the pad, both tips, GIc 0.004, GIIc 0.008 N/mm"),
    "c3": (lambda level: shipped("paper-fig7-cantilever-c3", (0.1, 0.3), level=level),
           "c3 cantilever, bottom debond at the clamp, its tip, GIc 0.1, GIIc 0.3 N/mm"),
}
