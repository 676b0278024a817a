"""Small scenes built in code for the beam-element tests (N, mm, MPa)."""

from sandwich.scene import (
    Analysis,
    BeamModelOptions,
    Debond,
    Layer,
    Load,
    Material,
    Probe,
    Scene,
    Support,
)


def isotropic(name, E, nu):
    return Material(name, "isotropic", E, E, E / (2 * (1 + nu)), nu)


KEVLAR = isotropic("kevlar", 27420.0, 0.3)
ROHACELL = Material("rohacell", "orthotropic", 52.5, 52.5, 21.0, 0.25)


def sandwich_scene(
    *,
    length=300.0,
    width=60.0,
    face=0.5,
    core=25.0,
    face_material=KEVLAR,
    core_material=ROHACELL,
    debonds=(),
    supports=None,
    loads=None,
    probes=None,
    elements=60,
    analysis=None,
    name="test",
    core_level=1,
):
    """Simply supported (bottom face, pin + roller) three-point bend unless told otherwise.

    ``core_level``: the beam's core level, 1 (the paper's element) unless a test asks for the
    hierarchy (``"auto"`` or a higher level).
    """
    if supports is None:
        supports = (Support(0.0, "bottom", "pin"), Support(length, "bottom", "roller"))
    if loads is None:
        loads = (Load("top", length / 2, 10.0, -1.0),)
    if probes is None:
        probes = (Probe("w_top_mid", "top", length / 2),
                  Probe("w_bottom_mid", "bottom", length / 2))
    return Scene(
        name=name, description="", length=length, width=width,
        top=Layer(face, face_material), core=Layer(core, core_material),
        bottom=Layer(face, face_material),
        debonds=tuple(debonds), supports=tuple(supports), loads=tuple(loads),
        probes=tuple(probes),
        analysis=analysis or Analysis(kind="linear", until_load_factor=1.0),
        beam_model=BeamModelOptions(elements=elements, core=core_level),
    )


__all__ = ["Debond", "Load", "Probe", "Support", "sandwich_scene", "KEVLAR", "ROHACELL",
           "isotropic"]


def assert_layer_derivatives(op, u, lengths, width=60.0, step=1e-6):
    """Check force = ∂energy/∂u and tangent = ∂force/∂u of one layer by central differences.

    Returns the layer's force and tangent at ``u``.
    """
    import numpy as np

    from sandwich.beam.element import layer_energy, layer_response

    f, K = layer_response(op, u, lengths, width)
    K_fd, f_fd = np.zeros_like(K), np.zeros_like(f)
    for a, d in enumerate(op.dofs):
        du = np.zeros_like(u)
        du[:, d] = step
        f_plus = layer_response(op, u + du, lengths, width, tangent=False)[0]
        f_minus = layer_response(op, u - du, lengths, width, tangent=False)[0]
        K_fd[:, :, a] = (f_plus - f_minus) / (2 * step)
        f_fd[:, a] = (layer_energy(op, u + du, lengths, width)
                      - layer_energy(op, u - du, lengths, width)) / (2 * step)
    assert np.max(np.abs(K - K_fd)) < 1e-6 * np.max(np.abs(K))
    assert np.max(np.abs(f - f_fd)) < 1e-6 * np.max(np.abs(f))
    return f, K
