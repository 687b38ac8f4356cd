"""The fractal (power-law) spectral model and its conventions (docs/conventions.rst
("Fractal conventions"), docs/math.rst §1).

Profiles: one-sided PSD in cycles per metre, ``Rq² = ∫ G(f) df``, with
``G(f) = C η^(2D-3) f^-(5-2D)`` (the paper's eq. 1): D is the fractal dimension
(1-2), C the amplitude coefficient (metres) at the resolution η, and
``A = C η^(2D-3)`` the ``psd_prefactor`` (G at f = 1 m⁻¹). β = 5 - 2D, H = 2 - D.

Maps: two-sided PSD ``P2(fx, fy)``, ``Sq² = ∬ P2``. An isotropic map of surface
dimension Ds (2-3) has ``P2 = C2 |f|^-(8-2Ds)``. rough reports for maps the C of the
profiles through the map (D = Ds - 1): ``C2 = C η^(2Ds-5) K(Ds)`` with
``K = Γ(α/2) / (2 √π Γ((α-1)/2))``, α = 8 - 2Ds, so a map and its profiles share one
C. ``C2`` is the map's ``psd_prefactor``.
"""

import math

from ..errors import InputError


def profile_exponent(dimension):
    """β = 5 - 2D of G ∝ f^-β, for a profile dimension D in (1, 2)."""
    check_dimension(dimension, profile=True)
    return 5.0 - 2.0 * dimension


def map_exponent(dimension):
    """α = 8 - 2Ds of P2 ∝ |f|^-α, for a surface dimension Ds in (2, 3)."""
    check_dimension(dimension, profile=False)
    return 8.0 - 2.0 * dimension


def check_dimension(dimension, profile):
    low, high = (1.0, 2.0) if profile else (2.0, 3.0)
    if not low < dimension < high:
        kind = "profile" if profile else "map (surface dimension Ds)"
        hint = (
            " — for a map give the surface dimension Ds = D + 1"
            if profile and 2 < dimension < 3
            else " — for a profile give D = Ds - 1"
            if not profile and 1 < dimension < 2
            else ""
        )
        raise InputError(f"a {kind} needs a fractal dimension between {low:g} and {high:g}, not {dimension:g}{hint}")


def prefactor(amplitude, dimension, resolution):
    """The profile PSD prefactor A = C η^(2D-3) (G at f = 1 m⁻¹)."""
    return amplitude * resolution ** (2.0 * dimension - 3.0)


def amplitude(prefactor_value, dimension, resolution):
    """The amplitude coefficient C = A η^(3-2D) at the resolution η."""
    return prefactor_value * resolution ** (3.0 - 2.0 * dimension)


def map_factor(surface_dimension):
    """K(Ds) = Γ(α/2) / (2 √π Γ((α-1)/2)): C2 = C η^(2Ds-5) K turns the profile C
    into the 2-D prefactor of the isotropic map whose profiles have that C."""
    alpha = map_exponent(surface_dimension)
    return math.gamma(alpha / 2) / (2 * math.sqrt(math.pi) * math.gamma((alpha - 1) / 2))


def map_prefactor(amplitude_value, surface_dimension, resolution):
    """C2 of P2 = C2 |f|^-(8-2Ds), from the profile-equivalent C at resolution η."""
    return amplitude_value * resolution ** (2.0 * surface_dimension - 5.0) * map_factor(surface_dimension)


def map_amplitude(prefactor_value, surface_dimension, resolution):
    """The profile-equivalent C of a map whose P2 prefactor is C2."""
    return prefactor_value / (resolution ** (2.0 * surface_dimension - 5.0) * map_factor(surface_dimension))


def structure_factor(dimension):
    """C_P / C_S: Ganti & Bhushan's structure-function coefficient C_S
    (S(τ) = C_S η^(2D-3) τ^(4-2D)) gives G with C_P = C_S · Γ(5-2D) sin(π(2-D)) /
    (π (2π)^(4-2D)) (docs/math.rst §1.2)."""
    return (
        math.gamma(5 - 2 * dimension)
        * math.sin(math.pi * (2 - dimension))
        / (math.pi * (2 * math.pi) ** (4 - 2 * dimension))
    )


def eq2_rq(amplitude_value, dimension, resolution, length, sampling=None):
    """The paper's eq. (2): the Rq that ∫ G df from 1/L to 1/τ predicts (τ = η by
    default). rough does not calibrate with it (docs/math.rst §2.5); it is here to compare."""
    tau = resolution if sampling is None else sampling
    exponent = 4.0 - 2.0 * dimension
    return math.sqrt(prefactor(amplitude_value, dimension, resolution) * (length**exponent - tau**exponent) / exponent)
