"""Independent numpy reference implementation ("oracle") of the spline-coupling model.

Written from the model specification only (docs/model.md restates it; equation numbers "Eq. N" are the paper's,
"docs/model.md s.N" are sections of the spec page).  It does not import anything from the
pyspline package; it exists so the Fortran/CVODE implementation can be checked against an
independent implementation to ~1e-12 relative, and as a plain-scipy benchmark baseline:

    from scipy.integrate import solve_ivp
    p = prepare(case)                      # optional: derive constants once
    sol = solve_ivp(lambda t, y: rhs(t, y, p), (0, 0.1), y0, method="DOP853")

Units: SI throughout, unscaled (the Eq. 25 scaling is an integrator concern, not part of
the model's right-hand side).

State vector (length 14):
    y[0:7]  = q  = [x1, y1, x2, y2, D1, D2, D3]            (m)
    y[7:14] = q' = d q / dt                                (m/s)
with D1 = r_b (th1 - thM), D2 = r_b (th2 - th1), D3 = r_b (th2 - thL)   (Eq. 24).

Public functions: prepare, mesh, rhs, energy, static_torsion
(helpers: flash_geometry, flash_temperature, coupled_residual).
"""

import math

import numpy as np

__all__ = ["Prepared", "prepare", "mesh", "rhs", "energy", "static_torsion",
           "flash_geometry", "flash_temperature", "coupled_residual", "random_spacing_errors"]

THERMAL_MODES = ("none", "bulk", "oneway", "coupled")

# Fixed-point iteration of the thermally coupled tooth force (docs/model.md s.6, Eq. 2):
# stop when successive iterates differ by <= _FP_RTOL*|F| (~2 ulp); the map contracts
# with factor ~ 0.75 * k_m * 2 lambda s cos(alpha) * T_f / |F|  (~1e-3 for the paper's
# values), so the remaining error is ~1e-3 of the last step, i.e. at rounding level.
_FP_RTOL = 4.5e-16
_FP_ATOL = 1.0e-300
_FP_MAXIT = 60


# --------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------
class Prepared:
    """Case parameters plus derived constants (computed once per case)."""

    def __init__(self, case):
        self.case = dict(case)
        g = lambda k: float(case[k])
        self.z = int(case["z"])
        if self.z < 1:
            raise ValueError("z must be a positive number of teeth")
        self.module_m = g("module_m")
        self.alpha = math.radians(g("alpha_deg"))
        self.b = g("b")
        self.s = g("s")
        self.c0 = g("c0")
        self.e_mod = g("e_mod")
        self.nu = g("nu")
        self.lambda_th = g("lambda_th")
        self.k_cond = g("k_cond")
        self.rho = g("rho")
        self.c_heat = g("c_heat")
        self.j_m, self.j_l, self.j_1, self.j_2 = g("j_m"), g("j_l"), g("j_1"), g("j_2")
        self.m_1, self.m_2 = g("m_1"), g("m_2")
        self.k_p1, self.k_p2 = g("k_p1"), g("k_p2")
        self.c_p1, self.c_p2 = g("c_p1"), g("c_p2")
        self.k_t1, self.k_t2 = g("k_t1"), g("k_t2")
        self.c_t1, self.c_t2 = g("c_t1"), g("c_t2")
        self.k_m, self.c_m = g("k_m"), g("c_m")
        self.t_d, self.t_l = g("t_d"), g("t_l")
        self.speed_rpm = g("speed_rpm")
        self.grav = g("grav")
        self.l_x, self.l_y = g("l_x"), g("l_y")
        self.thermal = str(case["thermal"]).lower()
        if self.thermal not in THERMAL_MODES:
            raise ValueError(f"thermal must be one of {THERMAL_MODES}, got {case['thermal']!r}")
        self.t_bulk = g("t_bulk")            # T_M, bulk temperature rise (Eq. 1)
        self.f_m = g("f_m")
        self.u_flash = g("u_flash")          # u = 0.83   (Eq. 3)
        self.eta_hertz = g("eta_hertz")      # eta = 1.127 (Eq. 4)
        # tooth spacing (index) errors e_j (docs/model.md s.11): tooth j of spline 1 sits e_j
        # ahead of its place along +dn, so its dead zone is met at dn_j + e_j; teeth not listed: 0
        e = np.zeros(self.z)
        given = np.asarray(case.get("spacing_error", []), dtype=float)[:self.z]
        e[:given.size] = given
        amp = float(case.get("spacing_error_amp", 0.0))
        if amp > 0.0:
            e = e + random_spacing_errors(self.z, amp, int(case.get("spacing_error_seed", 1)))
        self.e = e

        # Derived (convention 1 of the brief / docs/model.md s.2, s.8)
        self.omega = self.speed_rpm * 2.0 * math.pi / 60.0          # rad/s
        self.R = self.module_m * self.z / 2.0                        # pitch radius
        self.r_b = self.R * math.cos(self.alpha)                     # base radius
        # active profile (docs/model.md s.6): internal tip (minor) .. external tip (major) circle
        self.r_lo = self.module_m * (self.z - 1) / 2.0
        self.r_hi = self.module_m * (self.z + 1) / 2.0
        self.theta_0 = math.pi / (2.0 * self.z)                      # Eq. 9
        self.cos_a = math.cos(self.alpha)
        self.sin_a = math.sin(self.alpha)
        j = np.arange(1, self.z + 1, dtype=float)
        # phi_j(t) = 2 pi j / Z + omega t + theta_0 - alpha  (Eq. 8); evaluated in exactly
        # this left-to-right order at every call (see _phi).
        self.two_pi_j_over_z = 2.0 * math.pi * j / self.z
        # Eq. 2: c_j = c0 - 2 lambda s T_Bj cos(alpha) = c0 - th_coef * T_Bj
        self.th_coef = 2.0 * self.lambda_th * self.s * self.cos_a
        # Eq. 4 (Hertz half-width) material factor 2 (1 - nu^2) / E
        self.hertz = 2.0 * (1.0 - self.nu ** 2) / self.e_mod
        # Eq. 3 thermal contact coefficient g rho c (same steel for both splines)
        self.grc = self.k_cond * self.rho * self.c_heat


def random_spacing_errors(z, amp, seed):
    """docs/model.md s.11: MINSTD x <- 48271 x mod (2^31 - 1) from x = seed, 8 draws discarded,
    u_j = x / (2^31 - 1) for teeth 1..z, d_j = 2 u_j - 1, mean removed, scaled to max |e_j| = amp."""
    m31, x = 2 ** 31 - 1, seed
    for _ in range(8):
        x = 48271 * x % m31
    d = []
    for _ in range(z):
        x = 48271 * x % m31
        d.append(2.0 * (x / m31) - 1.0)
    mean = 0.0
    for v in d:
        mean += v
    mean /= z
    d = np.array(d) - mean
    return d * (amp / np.abs(d).max())


def prepare(case):
    """Return a Prepared object for `case` (a dict, or an already Prepared object)."""
    return case if isinstance(case, Prepared) else Prepared(case)


# --------------------------------------------------------------------------------------
# Mesh kinematics (Eqs. 8-11), flash temperature (Eqs. 3-7, 12-13), contact (Eqs. 2, 15-17)
# --------------------------------------------------------------------------------------
def _phi(t, p):
    """Eqs. 8-9: phi_j = 2 pi j / Z + omega t + theta_0 - alpha."""
    return p.two_pi_j_over_z + p.omega * t + p.theta_0 - p.alpha


def flash_geometry(t, y, case):
    """Contact radii and Hertz/velocity quantities of every tooth (Eqs. 5-7, 12-13).

    Returns dict with arrays rc1, rc2 (contact-point radii), Rc1, Rc2 (curvature radii
    R_i = r_ci sin(alpha_mi), Eqs. 5-6), v1, v2 (surface velocities, Eq. 7).
    Delta_1j = X1 cos phi + Y1 sin phi, Delta_2j = x2 cos phi + y2 sin phi (Eq. 12, as
    simplified in docs/model.md s.6). One contact point per tooth pair (docs/model.md s.6):
    the pair's pitch point P, the same for both splines; r_ci is its distance from spline i's
    centre shifted by Delta_i along the profile, held on the active profile.
    """
    p = prepare(case)
    y = np.asarray(y, dtype=float)
    phi = _phi(t, p)
    return _flash_geometry(phi, y, p)


def _flash_geometry(phi, y, p):
    x1, y1, x2, y2 = y[0], y[1], y[2], y[3]
    X1 = x1 + p.l_x
    Y1 = y1 + p.l_y
    cp, sp = np.cos(phi), np.sin(phi)
    d1 = X1 * cp + Y1 * sp                                          # Eq. 12 (spline 1)
    d2 = x2 * cp + y2 * sp                                          # Eq. 12 (spline 2)
    rc1 = _contact_radius(d1, p)
    rc2 = _contact_radius(d2, p)
    Rc1 = rc1 * np.sin(np.arccos(p.r_b / rc1))                      # Eqs. 5-6
    Rc2 = rc2 * np.sin(np.arccos(p.r_b / rc2))
    v1 = p.omega * rc1 * p.cos_a                                    # Eq. 7
    v2 = p.omega * rc2 * p.cos_a
    return {"rc1": rc1, "rc2": rc2, "Rc1": Rc1, "Rc2": Rc2, "v1": v1, "v2": v2}


def _contact_radius(delta, p):
    """|P - Delta u|: in the frame (u, its normal) the pitch point is P = R (cos a, sin a) and the
    shifted centre is (Delta, 0) (Eq. 13 as a distance), clipped to the active profile
    [internal tip circle, external tip circle]."""
    return np.clip(np.hypot(p.R * p.cos_a - delta, p.R * p.sin_a), p.r_lo, p.r_hi)


def flash_temperature(F, geo, case):
    """Blok flash temperature T_fj (Eq. 3 corrected: c_2 v_2 in the second root), Eq. 4.

    T_f = u f_m f_e |v1 - v2| / (sqrt(B) (sqrt(g rho c v1) + sqrt(g rho c v2))),
    f_e = |F|/b, B = eta sqrt(2(1-nu^2)/E |F|/b R1 R2/(R1+R2)); T_f = 0 where F == 0 or
    v1 = v2 = 0.  (sqrt of |v_i|: identical to the spec for omega >= 0, avoids NaN for a
    negative speed.)
    """
    p = prepare(case)
    absF = np.abs(np.asarray(F, dtype=float))
    v1, v2 = geo["v1"], geo["v2"]
    Rc1, Rc2 = geo["Rc1"], geo["Rc2"]
    fe = absF / p.b
    B = p.eta_hertz * np.sqrt(p.hertz * fe * (Rc1 * Rc2 / (Rc1 + Rc2)))
    den = np.sqrt(B) * (np.sqrt(p.grc * np.abs(v1)) + np.sqrt(p.grc * np.abs(v2)))
    num = p.u_flash * p.f_m * fe * np.abs(v1 - v2)
    ok = (absF > 0.0) & (den > 0.0)
    return np.where(ok, num / np.where(ok, den, 1.0), 0.0)


def _tooth_force(dn, ddn, c, p):
    """Eqs. 15-17: dead zone [-c, c]; F = k_m delta + c_m ddn if |dn| > c (strict)."""
    delta = np.where(dn > c, dn - c, np.where(dn < -c, dn + c, 0.0))
    contact = (dn > c) | (dn < -c)
    return np.where(contact, p.k_m * delta + p.c_m * ddn, 0.0), delta, contact


def _check_backlash(c):
    if np.any(c <= 0.0):
        raise ValueError("thermal interference: backlash c_j <= 0 (Eq. 2), min c_j = %r"
                         % float(np.min(c)))


def _solve_coupled(dn, ddn, geo, p):
    """Thermally coupled tooth force (docs/model.md s.6, Eqs. 1-2, 15-17, 3-4).

    Per tooth solve F = k_m delta(dn, c(T_f(|F|))) + c_m ddn with
    c = c0 - 2 lambda s (T_M + T_f) cos(alpha).  A tooth out of contact at c evaluated with
    T_f = 0 (the largest c, since T_f >= 0 only closes the backlash) has F = T_f = 0.
    For teeth in contact the side (dn > c or dn < -c) cannot change as c shrinks, and
    F = F0 +/- a K |F|^(3/4) with small a K: fixed-point iteration F <- G(F) started at F0
    (the T_f = 0 force), stopped when |F_{n+1} - F_n| <= 4.5e-16 |F_{n+1}| (2 ulp); teeth not
    converged after 60 iterations (only possible for |F| ~ 1e-9 N or below) are finished
    with brentq on the bracket [F0, F0 + sigma a K M^(3/4)], M = max(2|F0|, (2 a K)^4).
    Returns F, c, T_f, delta, contact.
    """
    c_base = np.full_like(dn, p.c0 - p.th_coef * p.t_bulk)
    _check_backlash(c_base)
    F0, delta0, contact = _tooth_force(dn, ddn, c_base, p)
    F = F0.copy()
    Tf = np.zeros_like(dn)
    idx = np.nonzero(contact)[0]
    if idx.size == 0:
        return F, c_base, Tf, delta0, contact
    sub = {k: v[idx] for k, v in geo.items()}
    dn_c, ddn_c = dn[idx], ddn[idx]
    sigma = np.where(dn_c > 0.0, 1.0, -1.0)          # delta = dn - sigma c

    # Per-tooth factors of Eqs. 3-4 that do not depend on F (hoisted out of the loop;
    # T_f below equals flash_temperature() up to rounding, and the final T_f is
    # re-evaluated with flash_temperature() itself).
    Req = sub["Rc1"] * sub["Rc2"] / (sub["Rc1"] + sub["Rc2"])
    S = np.sqrt(p.grc * np.abs(sub["v1"])) + np.sqrt(p.grc * np.abs(sub["v2"]))
    A = np.where(S > 0.0, p.u_flash * p.f_m * np.abs(sub["v1"] - sub["v2"])
                 / np.where(S > 0.0, S, 1.0), 0.0)

    def G(Fv):
        fe = np.abs(Fv) / p.b
        B = p.eta_hertz * np.sqrt(p.hertz * fe * Req)                     # Eq. 4
        Tfv = np.where(fe > 0.0, A * fe / np.sqrt(np.where(fe > 0.0, B, 1.0)), 0.0)  # Eq. 3
        cv = p.c0 - p.th_coef * (p.t_bulk + Tfv)      # Eq. 2 with T_B = T_M + T_f (Eq. 1)
        return p.k_m * (dn_c - sigma * cv) + p.c_m * ddn_c, cv, Tfv     # Eqs. 15-17

    Fc = F0[idx].copy()
    done = np.zeros(idx.size, dtype=bool)
    for _ in range(_FP_MAXIT):
        Fn, cv, _tf = G(Fc)
        if np.any(cv <= 0.0):
            _check_backlash(cv)
        done = np.abs(Fn - Fc) <= _FP_RTOL * np.abs(Fn) + _FP_ATOL
        Fc = Fn
        if np.all(done):
            break
    if not np.all(done):
        from scipy.optimize import brentq
        for k in np.nonzero(~done)[0]:
            one = {kk: vv[k:k + 1] for kk, vv in sub.items()}

            def h(f, k=k, one=one):
                tf = flash_temperature(np.array([f]), one, p)[0]
                cv = p.c0 - p.th_coef * (p.t_bulk + tf)
                return f - (p.k_m * (dn_c[k] - sigma[k] * cv) + p.c_m * ddn_c[k])

            f0 = F0[idx][k]
            if h(f0) == 0.0:
                Fc[k] = f0
                continue
            # aK from T_f = K |F|^(3/4) evaluated at |F| = 1 N
            aK = p.k_m * p.th_coef * flash_temperature(np.array([1.0]), one, p)[0]
            M = max(2.0 * abs(f0), (2.0 * aK) ** 4)
            f1 = f0 + sigma[k] * aK * M ** 0.75
            lo, hi = (f0, f1) if f0 < f1 else (f1, f0)
            Fc[k] = brentq(h, lo, hi, xtol=1e-300, rtol=4.0 * np.finfo(float).eps,
                           maxiter=500)
    F[idx] = Fc
    Tf[idx] = flash_temperature(Fc, sub, p)
    c = c_base.copy()
    c[idx] = p.c0 - p.th_coef * (p.t_bulk + Tf[idx])
    _check_backlash(c)
    delta = np.where(dn > c, dn - c, np.where(dn < -c, dn + c, 0.0))
    return F, c, Tf, delta, contact


def _kinematics(t, y, p):
    """Eqs. 8-11: phi_j, dn_j (with the spacing error e_j) and its total time derivative ddn_j
    (e_j is fixed on the tooth: no rate)."""
    phi = _phi(t, p)
    sp, cp = np.sin(phi), np.cos(phi)
    X1 = y[0] + p.l_x
    Y1 = y[1] + p.l_y
    ex, ey = X1 - y[2], Y1 - y[3]
    dn = ex * sp - ey * cp + y[5] + p.e                 # Eq. 11, tooth j shifted by e_j
    ddn = ((y[7] - y[9]) * sp - (y[8] - y[10]) * cp + y[12]
           + p.omega * (ex * cp + ey * sp))                               # d/dt of Eq. 11
    return phi, sp, cp, dn, ddn


def mesh(t, y, case):
    """All per-tooth mesh quantities at (t, y).

    Returns dict with arrays (length z): phi (Eqs. 8-9), dn (Eq. 11), ddn (its total time
    derivative), c (Eq. 2), F (Eqs. 15-17), Fx = F sin phi, Fy = F cos phi (Eq. 19 with
    phi_j, docs/model.md s.4), Tf (Eq. 3), rc1, rc2 (Eqs. 12-13); and scalars Tm (Eq. 22),
    kv = |Tm|/T_d, Fx1 = -sum F sin phi, Fy1 = +sum F cos phi (Eqs. 20-21 corrected).
    """
    p = prepare(case)
    y = np.asarray(y, dtype=float)
    phi, sp, cp, dn, ddn = _kinematics(t, y, p)
    geo = _flash_geometry(phi, y, p)
    F, c, Tf = _contact(dn, ddn, geo, p)
    Tm = p.r_b * np.sum(F)                                                # Eq. 22
    Fx1 = -np.dot(F, sp)                                                  # same as rhs
    Fy1 = np.dot(F, cp)
    return {"phi": phi, "dn": dn, "ddn": ddn, "c": c, "F": F,
            "Fx": F * sp, "Fy": F * cp, "Tf": Tf, "rc1": geo["rc1"], "rc2": geo["rc2"],
            "Tm": float(Tm), "kv": float(abs(Tm) / p.t_d) if p.t_d != 0.0 else float("nan"),
            "Fx1": float(Fx1), "Fy1": float(Fy1)}


def _contact(dn, ddn, geo, p):
    """Backlash (Eq. 2) by thermal mode, tooth force (Eqs. 15-17), flash temp (Eq. 3)."""
    mode = p.thermal
    if mode == "coupled":
        F, c, Tf, _, _ = _solve_coupled(dn, ddn, geo, p)
        return F, c, Tf
    T_B = 0.0 if mode == "none" else p.t_bulk
    c = np.full_like(dn, p.c0 - p.th_coef * T_B)                          # Eq. 2
    _check_backlash(c)
    F, _, _ = _tooth_force(dn, ddn, c, p)
    if mode == "oneway":
        Tf = flash_temperature(F, geo, p)          # reported only, no feedback into c
    else:
        Tf = np.zeros_like(dn)
    return F, c, Tf


def coupled_residual(t, y, case):
    """Max |F - G(F)| / max(|F|, 1e-300) of the coupled thermal relation at (t, y)."""
    p = prepare(case)
    y = np.asarray(y, dtype=float)
    phi, sp, cp, dn, ddn = _kinematics(t, y, p)
    geo = _flash_geometry(phi, y, p)
    F, c, Tf, _, contact = _solve_coupled(dn, ddn, geo, p)
    Tf2 = flash_temperature(F, geo, p)
    c2 = p.c0 - p.th_coef * (p.t_bulk + Tf2)
    G = np.where(dn > c2, p.k_m * (dn - c2), np.where(dn < -c2, p.k_m * (dn + c2), 0.0))
    G = np.where(contact, G + p.c_m * ddn, 0.0)
    r = np.abs(F - G) / np.maximum(np.abs(F), 1e-300)
    return float(np.max(r[contact])) if np.any(contact) else 0.0


# --------------------------------------------------------------------------------------
# Equations of motion (Eq. 23) reduced to 7 DOF (Eq. 24, re-derived)
# --------------------------------------------------------------------------------------
def rhs(t, y, case):
    """dy/dt of the 14-state reduced system (SI).

    Lateral (Eq. 23, gravity -m g on y):
        m1 x1'' = F_x1 - c_p1 x1' - k_p1 x1,   m1 y1'' = F_y1 - c_p1 y1' - k_p1 y1 - m1 g
        m2 x2'' = -F_x1 - c_p2 x2' - k_p2 x2,  m2 y2'' = -F_y1 - c_p2 y2' - k_p2 y2 - m2 g
    Torsional: with shaft torques S1 = (k_T1 D1 + c_T1 D1')/r_b = k_T1(th1-thM)+c_T1(..)'
    and S2 = (k_T2 D3 + c_T2 D3')/r_b = k_T2(th2-thL)+c_T2(..)', Eq. 23 gives
        J_M thM'' = T_d + S1,  J_1 th1'' = T_m - S1,  J_2 th2'' = -T_m - S2,
        J_L thL'' = -T_L + S2,
    hence (derived here; the paper's printed Eq. 24 has a sign slip on T_L):
        D1'' = r_b [ (T_m - S1)/J_1 - (T_d + S1)/J_M ]
        D2'' = r_b [ (-T_m - S2)/J_2 - (T_m - S1)/J_1 ]
        D3'' = r_b [ (-T_m - S2)/J_2 - (S2 - T_L)/J_L ]
    """
    p = prepare(case)
    y = np.asarray(y, dtype=float)
    phi, sp, cp, dn, ddn = _kinematics(t, y, p)
    if p.thermal in ("coupled",):
        geo = _flash_geometry(phi, y, p)
        F, _, _ = _contact(dn, ddn, geo, p)
    else:
        # 'oneway' only reports T_f; the dynamics do not need it.
        T_B = 0.0 if p.thermal == "none" else p.t_bulk
        c = p.c0 - p.th_coef * T_B                                        # Eq. 2
        if c <= 0.0:
            _check_backlash(np.array([c]))
        F, _, _ = _tooth_force(dn, ddn, c, p)                             # Eqs. 15-17
    Tm = p.r_b * np.sum(F)                                                # Eq. 22
    Fx1 = -np.dot(F, sp)                                                  # docs/model.md s.4
    Fy1 = np.dot(F, cp)

    x1, y1, x2, y2, D1, D2, D3 = y[0:7]
    vx1, vy1, vx2, vy2, dD1, dD2, dD3 = y[7:14]
    S1 = (p.k_t1 * D1 + p.c_t1 * dD1) / p.r_b
    S2 = (p.k_t2 * D3 + p.c_t2 * dD3) / p.r_b
    a1 = (Tm - S1) / p.j_1            # th1''
    aM = (p.t_d + S1) / p.j_m         # thM''
    a2 = (-Tm - S2) / p.j_2           # th2''
    aL = (S2 - p.t_l) / p.j_l         # thL''

    dy = np.empty(14)
    dy[0:7] = y[7:14]
    dy[7] = (Fx1 - p.c_p1 * vx1 - p.k_p1 * x1) / p.m_1
    dy[8] = (Fy1 - p.c_p1 * vy1 - p.k_p1 * y1) / p.m_1 - p.grav
    dy[9] = (-Fx1 - p.c_p2 * vx2 - p.k_p2 * x2) / p.m_2
    dy[10] = (-Fy1 - p.c_p2 * vy2 - p.k_p2 * y2) / p.m_2 - p.grav
    dy[11] = p.r_b * (a1 - aM)        # D1'' = r_b (th1'' - thM'')
    dy[12] = p.r_b * (a2 - a1)        # D2'' = r_b (th2'' - th1'')
    dy[13] = p.r_b * (a2 - aL)        # D3'' = r_b (th2'' - thL'')
    return dy


# --------------------------------------------------------------------------------------
# Invariants / closed forms for verification
# --------------------------------------------------------------------------------------
def energy(y, case):
    """Total mechanical energy in the conservative setting (no damping, no torques, no
    gravity, speed 0, thermal 'none' backlash c0).

    Rotational speeds are reconstructed from D1', D2', D3' (Eq. 24) under zero total angular
    momentum J_M thM' + J_1 th1' + J_2 th2' + J_L thL' = 0:
        th1' = thM' + D1'/r_b, th2' = th1' + D2'/r_b, thL' = th2' - D3'/r_b.
    E = sum m v^2/2 (x1,y1,x2,y2) + sum J th'^2/2 + k_p (x^2+y^2)/2 (both supports)
        + k_T1 (D1/r_b)^2/2 + k_T2 (D3/r_b)^2/2 + sum_j k_m delta_j^2/2 (docs/model.md s.4, V).
    """
    p = prepare(case)
    y = np.asarray(y, dtype=float)
    x1, y1, x2, y2, D1, D2, D3 = y[0:7]
    vx1, vy1, vx2, vy2, dD1, dD2, dD3 = y[7:14]
    u1, u2, u3 = dD1 / p.r_b, dD2 / p.r_b, dD3 / p.r_b
    J = np.array([p.j_m, p.j_1, p.j_2, p.j_l])
    rel = np.array([0.0, u1, u1 + u2, u1 + u2 - u3])       # speeds relative to thM'
    wM = -np.dot(J, rel) / np.sum(J)
    w = wM + rel
    ke = 0.5 * (p.m_1 * (vx1 ** 2 + vy1 ** 2) + p.m_2 * (vx2 ** 2 + vy2 ** 2)) \
        + 0.5 * np.dot(J, w ** 2)
    pe = 0.5 * (p.k_p1 * (x1 ** 2 + y1 ** 2) + p.k_p2 * (x2 ** 2 + y2 ** 2)) \
        + 0.5 * p.k_t1 * (D1 / p.r_b) ** 2 + 0.5 * p.k_t2 * (D3 / p.r_b) ** 2
    # mesh potential with the thermal-'none' dead zone [-c0, c0] at time t = 0 (speed 0,
    # so phi does not depend on t)
    phi, sp, cp, dn, ddn = _kinematics(0.0, y, p)
    c = p.c0
    delta = np.where(dn > c, dn - c, np.where(dn < -c, dn + c, 0.0))
    pe += 0.5 * p.k_m * np.sum(delta ** 2)
    return float(ke + pe)


def static_torsion(case):
    """Closed-form static tooth-force magnitude T_d / (Z r_b) for an aligned case (all
    teeth share the load equally, Eq. 22 with T_m = -T_d gives F_j = -T_d/(Z r_b))."""
    p = prepare(case)
    return p.t_d / (p.z * p.r_b)
