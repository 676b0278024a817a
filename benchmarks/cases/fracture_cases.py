"""Scenes with a closed-form energy release rate, shared by the beam and the 2D tests.

Beam on the x axis, L = 200 mm, b = 20 mm, faces t = 1 mm (E = 70 GPa, ν = 0.3), core 10 mm
(isotropic E = 200 MPa, ν = 0.3 unless changed), faces clamped at x = L, top interface debonded
over [0, a] (an open mouth at x = 0, one tip at x = a). Loads are transverse point forces on the
faces at x = 0 and x = d = 20 mm.

Closed forms (linear elasticity; steady state, i.e. a − d and L − a several thicknesses):

- couple M = P d on the debonded face only ("peel"): in [d, a] the face carries M with no shear
  and no axial force, the substrate (core + bottom face) carries nothing, and the bonded section
  ahead carries M. The J-integral around the tip (the energy per length of the sections far
  behind minus far ahead; pure bending of a layered strip is exact beam theory):
  G = M²/(2b) · [1/EI_face − 1/EI_all];
- couples split as M_face : M_substrate = EI_face : EI_substrate on the face and on the bottom
  face ("mode II"): both parts behind the tip bend with the same curvature M/(EI_face +
  EI_substrate), the lips neither open nor press, and only slide:
  G = M²/(2b) · [1/(EI_face + EI_substrate) − 1/EI_all], the sliding (mode II) partition;
- a single transverse force P at the face's end ("cantilever"): beam theory on a rigid
  substrate gives G = 6 P² a² / (b² E t³) = P² a²/(2 b EI_face). The core's compliance rotates
  the root: G = 6 P² (a + χ t)² / (b² E t³) with χ independent of a, so d√G/da = √6 P/(b
  √(E t³)) is the closed-form check that does not depend on χ.

EI is about the modulus-weighted centroid of the section (E_x of each layer; plane stress).
"""

from sandwich.scene_checks import build_scene

E_FACE, NU = 70000.0, 0.3
T_FACE, H_CORE, WIDTH, LENGTH, D_COUPLE = 1.0, 10.0, 20.0, 200.0, 20.0


def scene(loads, *, a=60.0, e_core=200.0, level="coarse", elements=240, until=0.1,
          probe_on="top", tol=None, mirror=False, core=1):
    """The debonded strip with ``loads`` (list of (face, x, force)), displacement-controlled.

    The path is driven by w of ``probe_on`` at x = 0 up to ``until`` mm (small: G is a linear
    elasticity check; 0.1 mm is 0.1 % of a face rotation). ``mirror``: the same problem
    reflected about mid-span (x -> L - x), whose tip is the debond's ``start``. ``core``: the
    beam's core level (1 = the paper's element; "auto" = the scene default since 2026-12-01).
    """
    def at(x):
        return LENGTH - x if mirror else x

    analysis = {"kind": "nonlinear", "control": "displacement",
                "until": {"probe": "w0", "value": until}}
    if tol is not None:
        analysis["tol"] = tol
    data = {
        "name": "fracture-check", "description": "closed-form G check",
        "beam": {"length": LENGTH, "width": WIDTH},
        "layers": {"top": {"thickness": T_FACE, "material": "face"},
                   "core": {"thickness": H_CORE, "material": "core"},
                   "bottom": {"thickness": T_FACE, "material": "face"}},
        "materials": {"face": {"E": E_FACE, "nu": NU}, "core": {"E": e_core, "nu": NU}},
        "supports": [{"x": at(LENGTH), "on": "faces", "type": "clamp"}],
        "loads": [{"on": f, "x": at(x), "width": 0.0, "force": p} for f, x, p in loads],
        "debonds": [{"interface": "top", "start": min(at(0.0), at(a)),
                     "end": max(at(0.0), at(a))}],
        "probes": [{"name": "w0", "on": probe_on, "x": at(0.0)}],
        "analysis": analysis,
        "reference2d": {"level": level},
        "beam_model": {"elements": elements, "core": core},
    }
    return build_scene(data, "<fracture-check>")


def section_ei(layers, width=WIDTH):
    """Bending stiffness (N mm²) of layers [(z_lo, z_hi, E)] about their weighted centroid."""
    ea = sum(E * (zh - zl) for zl, zh, E in layers)
    zc = sum(E * (zh - zl) * 0.5 * (zh + zl) for zl, zh, E in layers) / ea
    return width * sum(E * ((zh - zc) ** 3 - (zl - zc) ** 3) / 3.0 for zl, zh, E in layers)


def stiffnesses(sc):
    """EI of the top face, of the substrate (core + bottom face) and of the whole section."""
    hc, t = sc.core.thickness, sc.top.thickness
    top = (hc / 2, hc / 2 + t, sc.top.material.Ex)
    core = (-hc / 2, hc / 2, sc.core.material.Ex)
    bot = (-hc / 2 - sc.bottom.thickness, -hc / 2, sc.bottom.material.Ex)
    return section_ei([top]), section_ei([core, bot]), section_ei([top, core, bot])


def peel_loads(p=1.0):
    """Couple P d on the top face: +P (up, opening) at x = 0, −P at x = d."""
    return [("top", 0.0, p), ("top", D_COUPLE, -p)]


def peel_g(sc, load_factor, p=1.0):
    """Closed-form G (N/mm) of the peel couple at ``load_factor``."""
    ei_f, _, ei_all = stiffnesses(sc)
    m = load_factor * p * D_COUPLE
    return m**2 / (2 * sc.width) * (1 / ei_f - 1 / ei_all)


def shear_loads(sc, p=1.0):
    """Couples on both faces in the ratio EI_face : EI_substrate (total P d): pure sliding."""
    ei_f, ei_s, _ = stiffnesses(sc)
    pf, ps = p * ei_f / (ei_f + ei_s), p * ei_s / (ei_f + ei_s)
    return [("top", 0.0, pf), ("top", D_COUPLE, -pf), ("bottom", 0.0, ps),
            ("bottom", D_COUPLE, -ps)]


def shear_g(sc, load_factor, p=1.0):
    """Closed-form G (N/mm) of the split couples at ``load_factor`` (all mode II)."""
    ei_f, ei_s, ei_all = stiffnesses(sc)
    m = load_factor * p * D_COUPLE
    return m**2 / (2 * sc.width) * (1 / (ei_f + ei_s) - 1 / ei_all)


def cantilever_slope(sc, load_factor, p=1.0):
    """Closed-form d√G/da (√(N/mm)/mm) of an end force P on the face: √6 P / (b √(E t³))."""
    return (6.0 ** 0.5) * load_factor * p / (sc.width * (sc.top.material.Ex
                                                         * sc.top.thickness**3) ** 0.5)
