"""One gear tooth for the potential-energy mesh stiffness (:mod:`.gear_mesh`): its face-width
law (constant, or the threaded roller tooth's), its involute and fillet geometry and its
bending, shear, axial and foundation compliances at a contact point, a crack or a pit included
(:mod:`.tooth_damage`).

References (full list in :mod:`.gear_mesh`)
----------
- Paper 01 §2.1 (k_b, k_s, k_a integrals; the threaded roller tooth's width L_a(x)).
- D.C.H. Yang, J.Y. Lin, "Hertzian damping, tooth friction and bending elasticity in gear
  impact dynamics", J. Mech. Trans. Autom. Des. 109 (1987) 189–196 (shear factor 1.2).
- P. Sainsot, P. Velex, O. Duverger, "Contribution of gear body to tooth deflections — a new
  bidimensional analytical formula", J. Mech. Des. 126 (2004) 748–752 (Table 1).
- Z. Chen, Y. Shao, "Mesh stiffness calculation of a spur gear pair with tooth profile
  modification and tooth root crack", Mech. Mach. Theory 62 (2013) 63–74 (fillet).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from .tooth_damage import damaged_sections

#: Sainsot et al. (2004) Table 1: rows L*, M*, P*, Q*; columns A_i … F_i of
#: X = A/θ_f² + B·h_fi² + C·h_fi/θ_f + D/θ_f + E·h_fi + F.
SAINSOT_COEFFICIENTS = np.array(
    [
        [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
        [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
        [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
        [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
    ]
)

# Gauss–Legendre rule per integration panel. The integrands are analytic within a panel
# (panels split at every kink of the width law), so 32 nodes reach ~1e-12 relative error.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(32)

_SHEAR_FACTOR = 1.2  # rectangular section (Yang & Lin 1987)


def involute_function(a):
    """Involute function inv α = tan α − α."""
    return np.tan(a) - a


# ============================================================================ width laws
class WidthLaw:
    """Face width of a tooth section as a function of its radius: constant, or the threaded
    roller tooth's (module docstring; :func:`mesh_stiffness`'s ``thread_*`` parameters).

    ``kinks`` are the radii where the law has a corner; integration panels split there.
    """

    def __init__(
        self,
        face_width,
        *,
        threaded=False,
        reading="envelope",
        crest_fraction=1.0,
        full_radius=0.0,
        crest_radius=1.0,
    ):
        self.L = face_width
        self.threaded = threaded
        self.reading = reading
        self.fc = crest_fraction
        self.r_full = full_radius
        self.r_crest = crest_radius
        self.kinks = (full_radius, crest_radius) if threaded else ()

    def __call__(self, r):
        r = np.asarray(r, dtype=float)
        if not self.threaded:
            return np.full(r.shape, self.L)
        span = self.r_crest - self.r_full
        if self.reading == "envelope":
            # Thread land: full pitch below x_B, narrowing linearly to the crest at x_A.
            s = np.clip((self.r_crest - r) / span, 0.0, 1.0)
        else:
            # Paper 01 as printed: full width at the tip x_A, narrowing towards x_B.
            s = np.clip((r - self.r_full) / span, 0.0, 1.0)
        return self.L * (self.fc + (1.0 - self.fc) * s)


# ============================================================================== the teeth
def _sainsot(theta_f: float, h_fi: float) -> np.ndarray:
    """Coefficients (L*, M*, P*, Q*) of Sainsot et al. (2004)."""
    c = SAINSOT_COEFFICIENTS
    terms = np.array([1 / theta_f**2, h_fi**2, h_fi / theta_f, 1 / theta_f, h_fi, 1.0])
    return c @ terms


def _panel_nodes(lo, hi):
    """Gauss–Legendre nodes and weights on [lo, hi] (arrays broadcast, last axis = nodes)."""
    lo = np.asarray(lo, dtype=float)[..., None]
    hi = np.asarray(hi, dtype=float)[..., None]
    half = 0.5 * (hi - lo)
    return lo + half * (_GL_X + 1.0), half * _GL_W


class ToothGeometry:
    """Geometry and compliance of one tooth (pinion, external gear or ring gear).

    Flank points are parametrised by t = tan α_r (α_r the pressure angle at radius r, so
    r = r_b·√(1 + t²)); the line of action touches the flank at roll distance r_b·t from the
    tangent point on the base circle. ``nu`` (Poisson's ratio, for the Hertz term) is only
    kept for the mesh.
    """

    def __init__(self, z, m, alpha, ha, hf, *, internal, width, E, G, h_fi, tip_ha=None, nu=None):
        # ha, hf: basic-rack (tool) proportions; tip_ha: this tooth's addendum if shortened.
        tip_ha = ha if tip_ha is None else tip_ha
        self.z, self.m, self.alpha, self.internal = z, m, alpha, internal
        self.E, self.G, self.nu, self.width, self.h_fi = E, G, nu, width, h_fi
        self.tip_ha = tip_ha
        self.rp = z * m / 2.0
        self.rb = self.rp * math.cos(alpha)
        if internal:
            self.ra = self.rp - tip_ha * m
            self.rf = self.rp + hf * m
            # Half tooth angle of the ring tooth at its base circle (negative for big rings).
            self.c = math.pi / (2 * z) - float(involute_function(alpha))
            self.t_root = math.sqrt((self.rf / self.rb) ** 2 - 1.0)
            self.t_tip = math.sqrt(max((self.ra / self.rb) ** 2 - 1.0, 0.0))
            self.theta_f = self.c + float(involute_function(math.atan(self.t_root)))
            self.y_root = float(self.involute(self.t_root)[0])
            self.t_usable = self.t_root  # involute all the way to the root circle
        else:
            self.ra = self.rp + tip_ha * m
            self.rf = self.rp - hf * m
            self.a2 = math.pi / (2 * z) + float(involute_function(alpha))  # half tooth angle at r_b
            self.t_tip = math.sqrt((self.ra / self.rb) ** 2 - 1.0)
            self._setup_rack(ha, hf)
            self.theta_f = self.u_c / self.rp
            self.y_root = self.rf * math.cos(self.theta_f)
            self._find_junction()
        self.S_f = 2.0 * self.rf * self.theta_f
        self.width_root = float(width(self.rf))
        self.sainsot = _sainsot(self.theta_f, h_fi)

    # ------------------------------------------------------------------ geometry
    def involute(self, t):
        """Section coordinate y (from the gear centre), half thickness h, dy/dt."""
        t = np.asarray(t, dtype=float)
        rb = self.rb
        if self.internal:
            a = self.c + t
            y = rb * (np.cos(a) + t * np.sin(a))
            h = rb * (np.sin(a) - t * np.cos(a))
        else:
            a = self.a2 - t
            y = rb * (np.cos(a) - t * np.sin(a))
            h = rb * (np.sin(a) + t * np.cos(a))
        return y, h, rb * t * np.cos(a)

    def load_angle(self, t):
        """Angle α₁ between the line of action and the normal to the tooth centreline."""
        return (self.c + t) if self.internal else (t - self.a2)

    def _setup_rack(self, ha, hf):
        m, alpha = self.m, self.alpha
        # ISO 53-type cutter: tip radius so that the straight flank ends at depth h_a·m.
        self.rho = (hf - ha) * m / (1.0 - math.sin(alpha))
        self.v_c = hf * m - self.rho
        self.u_c = math.pi * m / 4 + self.v_c * math.tan(alpha) + self.rho / math.cos(alpha)
        self.h_l = hf * m - self.rho * (1.0 - math.sin(alpha))

    def fillet(self, g):
        """Generated fillet at normal angle γ ∈ [α, π/2] (π/2: root circle).

        Returns y, h, dy/dγ, r. The cutter tip-circle point whose normal passes through the
        pitch point (Camus) generates the fillet; rotating back by the roll angle gives the
        point in tooth coordinates.
        """
        g = np.asarray(g, dtype=float)
        rho, v_c, u_c, rp = self.rho, self.v_c, self.u_c, self.rp
        cot = np.cos(g) / np.sin(g)
        x = -rho * np.cos(g) - v_c * cot
        y0 = rp - v_c - rho * np.sin(g)
        phi = -(u_c + v_c * cot) / rp
        dx = rho * np.sin(g) + v_c / np.sin(g) ** 2
        dy0 = -rho * np.cos(g)
        dphi = v_c / (rp * np.sin(g) ** 2)
        h = x * np.cos(phi) - y0 * np.sin(phi)
        y = x * np.sin(phi) + y0 * np.cos(phi)
        dy = dx * np.sin(phi) + dy0 * np.cos(phi) + h * dphi
        return y, h, dy, np.hypot(x, y0)

    def _fillet_angle(self, g):
        """Polar angle of the fillet point from the tooth centreline and its radius."""
        y, h, _, r = self.fillet(g)
        return np.arctan2(h, y), r

    def _involute_angle(self, r):
        t = np.sqrt(np.maximum((r / self.rb) ** 2 - 1.0, 0.0))
        return self.a2 - (t - np.arctan(t))

    def _find_junction(self):
        """Lowest usable involute point: form point, or the undercut crossing."""
        alpha = self.alpha
        s_form = self.rp * math.sin(alpha) - self.h_l / math.sin(alpha)
        if s_form >= 0.0:
            # Fillet and involute join tangentially at the form point.
            self.g_junction = alpha
            self.t_usable = s_form / self.rb
            self.undercut = False
            return
        # Undercut: the fillet top (γ = α, generated beyond N1) lies outside the involute and
        # the fillet crosses into it above the base circle; that crossing is the junction.
        self.undercut = True

        def gap(g):
            th, r = self._fillet_angle(g)
            return float(th - self._involute_angle(r))

        # The involute exists only for r ≥ r_b: search γ ∈ [α, γ_b], r(γ_b) = r_b (r falls
        # monotonically with γ along the fillet).
        if self.rf < self.rb:
            g_b = brentq(
                lambda g: float(self.fillet(g)[3]) - self.rb, alpha, math.pi / 2, xtol=1e-15
            )
        else:  # pragma: no cover - undercut needs r_f < r_b for standard proportions
            g_b = math.pi / 2
        if gap(g_b) >= 0.0:
            # The fillet stays outside the involute down to the base circle: the whole
            # involute is usable and the boundary steps onto the fillet there.
            self.g_junction = g_b
        else:
            gs = np.linspace(alpha, g_b, 401)
            th, r = self._fillet_angle(gs)
            d = th - self._involute_angle(r)
            i = int(np.nonzero((d[:-1] > 0) & (d[1:] <= 0))[0][0])
            self.g_junction = brentq(gap, gs[i], gs[i + 1], xtol=1e-15)
        r_j = float(self._fillet_angle(self.g_junction)[1])
        self.t_usable = math.sqrt(max((r_j / self.rb) ** 2 - 1.0, 0.0))

    # --------------------------------------------------------------- quadrature
    def radius(self, t):
        """Radius of the flank point at t = tan α_r: r_b·√(1 + t²)."""
        return self.rb * np.sqrt(1.0 + np.asarray(t, dtype=float) ** 2)

    def t_of_radius(self, r):
        """t = tan α_r of the flank point at radius r (0 at or below the base circle)."""
        return math.sqrt(max((r / self.rb) ** 2 - 1.0, 0.0))

    def _fillet_sections(self):
        """Contact-independent sections of the fillet: ζ, h, w, dζ·weight (1-D)."""
        edges = [self.g_junction, math.pi / 2]
        for rk in self.width.kinks:
            # r decreases monotonically from the junction to the root along the fillet.
            r_top = float(self.fillet(self.g_junction)[3])
            if self.rf < rk < r_top:
                edges.append(
                    brentq(
                        lambda g, rk=rk: float(self.fillet(g)[3]) - rk,
                        self.g_junction,
                        math.pi / 2,
                        xtol=1e-15,
                    )
                )
        edges = np.sort(np.asarray(edges))
        nodes, weights = _panel_nodes(edges[:-1], edges[1:])
        g, wq = nodes.ravel(), weights.ravel()
        y, h, dy, r = self.fillet(g)
        # y grows from the root to the junction while γ falls, so dζ = −dy/dγ·dγ.
        return y - self.y_root, h, self.width(r), -dy * wq

    def _involute_sections(self, t_c):
        """Per-contact involute sections between the usable start (or root) and t_c."""
        t_c = np.asarray(t_c, dtype=float)
        if self.internal:
            # Ring tooth: sections from the contact point out to the root circle.
            nodes, weights = _panel_nodes(t_c, np.full_like(t_c, self.t_root))
            y, h, dy = self.involute(nodes)
            return self.y_root - y, h, self.width(self.radius(nodes)), dy * weights
        edges = [np.full_like(t_c, self.t_usable)]
        for rk in self.width.kinks:
            tk = self.t_of_radius(rk) if rk > self.rb else self.t_usable
            edges.append(np.clip(np.full_like(t_c, tk), self.t_usable, t_c))
        edges.append(t_c)
        edges = np.sort(np.stack(edges, axis=-1), axis=-1)
        nodes, weights = _panel_nodes(edges[:, :-1], edges[:, 1:])
        nodes = nodes.reshape(t_c.size, -1)
        weights = weights.reshape(t_c.size, -1)
        y, h, dy = self.involute(nodes)
        return y - self.y_root, h, self.width(self.radius(nodes)), dy * weights

    def compliances(self, t_c, damage=None):
        """Bending, shear, axial and foundation compliances [m/N] at contact parameters t_c.

        Vectorised over contacts: every contact gets its own Gauss–Legendre panels on the
        involute (the upper limit is the contact point) and shares the fillet sections.
        ``damage`` (:mod:`prsm_health.physics.stiffness.tooth_damage`) replaces the sections' area and
        second moment where a crack or pit removes material.
        """
        t_c = np.asarray(t_c, dtype=float)
        y_c, h_c, _ = self.involute(t_c)
        zeta_c = (self.y_root - y_c) if self.internal else (y_c - self.y_root)
        a1 = self.load_angle(t_c)
        cos1, sin1 = np.cos(a1), np.sin(a1)

        zeta, h, w, dz = self._involute_sections(t_c)
        if not self.internal:
            zf, hf_, wf, dzf = self._fillet_sections()
            n = t_c.size
            zeta = np.concatenate([zeta, np.broadcast_to(zf, (n, zf.size))], axis=1)
            h = np.concatenate([h, np.broadcast_to(hf_, (n, hf_.size))], axis=1)
            w = np.concatenate([w, np.broadcast_to(wf, (n, wf.size))], axis=1)
            dz = np.concatenate([dz, np.broadcast_to(dzf, (n, dzf.size))], axis=1)

        arm = (zeta_c[:, None] - zeta) * cos1[:, None] - (h_c * sin1)[:, None]
        if damage is None:
            area, inertia = 2.0 * h * w, w * (2.0 * h) ** 3 / 12.0
        else:
            area, inertia = damaged_sections(damage, self, zeta, h, w)
        inv_area = dz / area
        bending = np.sum(arm**2 * dz / inertia, axis=1) / self.E
        shear = _SHEAR_FACTOR * cos1**2 * np.sum(inv_area, axis=1) / self.G
        axial = sin1**2 * np.sum(inv_area, axis=1) / self.E

        # Sainsot: u_f from the root circle to where the line of action crosses the centreline.
        if self.internal:
            u_f = self.rf - (y_c + h_c * np.tan(a1))
        else:
            u_f = (y_c - h_c * np.tan(a1)) - self.rf
        lf, mf, pf, qf = self.sainsot
        ratio = u_f / self.S_f
        foundation = (
            cos1**2
            / (self.E * self.width_root)
            * (lf * ratio**2 + mf * ratio + pf * (1.0 + qf * np.tan(a1) ** 2))
        )
        return bending, shear, axial, foundation


# ============================================================================ validation
