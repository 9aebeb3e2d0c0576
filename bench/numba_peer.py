"""The strongest "peer" a Python user could assemble: compiled LSODA (numbalsoda, ODEPACK's
LSODA in C) driving a numba-compiled right-hand side written from the model specification (docs/model.md restates it).

Independent of the Fortran core and of the pyspline package (it imports neither). The case
parameters come from tests/oracle.py's `prepare` (the same dict of case fields the oracle takes),
so this RHS and the numpy oracle read one parameter set; the numbers are then packed into one
float64 array `data` that numbalsoda hands to the compiled RHS at every call.

Model (docs/model.md; equation numbers are the paper's):
  phi_j = 2 pi j/Z + omega t + theta_0 - alpha, theta_0 = pi/(2Z)            Eqs. 8-9
  dn_j  = (X1 - x2) sin phi_j - (Y1 - y2) cos phi_j + D2,  X1 = x1+l_x ...    Eq. 11
          (r_b (th2 - th1) = D2, Eq. 24)
  c_j   = c0 - 2 lambda s T_B cos(alpha)                                       Eq. 2
  F_j   = k_m delta_j + c_m ddn_j  if |dn_j| > c_j, else 0 (dead zone)         Eqs. 15-17
  F_x1  = -sum F_j sin phi_j, F_y1 = +sum F_j cos phi_j, T_m = r_b sum F_j    Eqs. 19-22 (MODEL s.4)
  Eq. 23 reduced to D1, D2, D3 (Eq. 24, re-derived: the paper's T_L sign slip fixed).
Thermal levels: 'none' (T_B = 0), 'bulk' (T_B = T_M), 'oneway' (dynamics identical to 'bulk';
T_f is only reported, which this peer does not do), 'coupled' (T_B = T_M + T_fj with the Blok
flash temperature, Eqs. 3-7, 12-13, solved per tooth by fixed-point iteration to 2 ulp as the
oracle does, bisection fallback for teeth that do not converge in 60 iterations).

Two compiled right-hand sides. The fast one (every thermal level but 'coupled', with spacing
errors) is the race's: every constant folded into the scaled units of Eq. 25 when the case is
packed, the tooth phases as two dot products with precomputed cos/sin(2 pi j/Z) (one sin and one
cos per call), the tooth loop branch-free (max/min for the dead zone) and compiled with fastmath,
no allocation (see the block above _rhs_fast). The general one (every level, the coupled
iteration; no spacing errors) keeps the SI form with the scaling applied per state. Measured in
CPU time on one run (issue 34; DOP853 at equal rtol, paper_lx1e-4 and physical_z24) the general
RHS took 1.4x and 1.9x the fast one's time.

Scaling (Eq. 25): numbalsoda takes one scalar atol, so `solve` integrates the scaled system
u = q / l, u' = q' / (l w), tau = w t (l = c0, w = shaft speed unless the case sets l_ref,
w_ref), exactly as the project's CVODE integration does: atol is on the scaled states, i.e.
atol*l [m] on lengths and atol*l*w [m/s] on velocities.

Public names:
  Setup(params, scaled=True, kind=None)      a case packed once: .integrate(y0, t_eval, rtol,
                                             atol, method, mxstep) -> (u scaled, ok);
                                             .forces(t_eval, u) -> (T_m, F) in SI;
                                             .run(...) -> (T_m, F, ok) on the case's frozen
                                             RHS (the race)
  make_rhs(params, scaled=True, kind=None) -> (cfunc, data)   numbalsoda-compatible RHS, data
  solve(params, y0, t_eval, rtol=1e-8, atol=1e-10, mxstep=1_000_000, scaled=True,
        method='lsoda', kind=None)   -> (y, success, n_rhs)   y in SI, shape (len(t_eval), 14)
  rhs_eval(params, t, y, scaled=False, kind=None) -> dy/dt    one call of the compiled RHS (tests)
  load_case(path_or_dict, **overrides) -> dict         case fields with the core's defaults
"""
import ctypes
import math
import sys
import time
from pathlib import Path

import numpy as np
import numba as nb
from numba import cfunc, types

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "tests") not in sys.path:
    sys.path.insert(0, str(ROOT / "tests"))
import oracle  # noqa: E402

__all__ = ["Setup", "make_rhs", "solve", "rhs_eval", "load_case", "DEFAULTS", "lsoda_sig",
           "COMPILE_SECONDS", "compile_all"]

# numbalsoda's RHS signature: void f(double t, double *u, double *du, double *data)
lsoda_sig = types.void(types.double, types.CPointer(types.double),
                       types.CPointer(types.double), types.CPointer(types.double))

# Defaults of every model field (the component defaults of `case_t`, fortran/input/case_type.f90, values only; docs/model.md s.8).
DEFAULTS = dict(
    z=16, module_m=2.0e-3, alpha_deg=30.0, b=0.03, s=3.14e-3, c0=2.0e-4, e_mod=2.1e11, nu=0.3,
    lambda_th=1.2e-5, k_cond=46.47, rho=7800.0, c_heat=481.48,
    j_m=7.54e-3, j_l=7.52e-3, j_1=3.43e-3, j_2=3.73e-3, m_1=2.0, m_2=2.0,
    k_p1=5.0e6, k_p2=5.0e6, c_p1=5.0, c_p2=5.0, k_t1=7.855, k_t2=7.856, c_t1=0.191, c_t2=0.196,
    k_m=0.0, c_m=0.053, t_d=30.7, t_l=30.7, speed_rpm=6000.0, grav=9.81, l_x=0.0, l_y=0.0,
    thermal="none", t_bulk=0.0, f_m=0.1, u_flash=0.83, eta_hertz=1.127,
    method="bdf", rtol=1.0e-8, atol=1.0e-10, t0=0.0, t_end=0.1, n_out=1001,
    start="equilibrium", dq0=[0.0] * 7, dv0=[0.0] * 7, l_ref=0.0, w_ref=0.0,
)


def load_case(case, **overrides):
    """Case fields as a dict: a namelist file (&spline_case, read with f90nml) or a dict, over
    DEFAULTS, then `overrides`. k_m must be set (> 0): this peer does not compute Eq. 18."""
    if isinstance(case, (str, Path)):
        import f90nml
        fields = dict(f90nml.read(str(case))["spline_case"])
    else:
        fields = dict(case)
    out = dict(DEFAULTS)
    out.update(fields)
    out.update(overrides)
    return out


# --------------------------------------------------------------------------------------------
# Layout of the parameter array `data` (float64). Slot 0 counts RHS calls, slot 1 is an error
# flag (1: thermal interference, c_j <= 0, found inside the coupled iteration).
# --------------------------------------------------------------------------------------------
_NAMES = ("ncalls", "err", "z", "omega", "phase0", "l_x", "l_y", "c", "k_m", "c_m", "r_b",
          "k_p1", "c_p1", "m_1", "k_p2", "c_p2", "m_2", "grav",
          "k_t1", "c_t1", "k_t2", "c_t2", "j_1", "j_m", "j_2", "j_l", "t_d", "t_l",
          "l_ref", "w_ref",
          # coupled thermal level
          "coupled", "c0", "th_coef", "t_bulk", "b", "eta_hertz", "hertz", "grc", "uf",
          "R", "cos_a", "r_lo", "r_hi")
_I = {n: i for i, n in enumerate(_NAMES)}
_NSCAL = len(_NAMES)
# slot indices, in the order of _NAMES; after them cos(2 pi j/Z), j = 1..Z, then sin(2 pi j/Z)
(_NCALLS, _ERR, _Z, _OMEGA, _PHASE0, _L_X, _L_Y, _C, _K_M, _C_M, _R_B, _K_P1, _C_P1, _M_1,
 _K_P2, _C_P2, _M_2, _GRAV, _K_T1, _C_T1, _K_T2, _C_T2, _J_1, _J_M, _J_2, _J_L, _T_D, _T_L,
 _L_REF, _W_REF, _COUPLED, _C0, _TH_COEF, _T_BULK, _B, _ETA_HERTZ, _HERTZ, _GRC, _UF, _R,
 _COS_A, _R_LO, _R_HI) = range(_NSCAL)

_FP_RTOL = 4.5e-16      # as tests/oracle.py: successive iterates within 2 ulp
_FP_ATOL = 1.0e-300
_FP_MAXIT = 60


def _pack(params, scaled):
    """Pack a case (dict or oracle.Prepared) into the `data` array of the compiled RHS."""
    p = oracle.prepare(params)
    if p.thermal == "coupled":
        c = p.c0 - p.th_coef * p.t_bulk          # without flash: the largest the backlash gets
    else:                                        # 'oneway': T_f does not feed back (MODEL s.6)
        c = p.c0 - p.th_coef * (0.0 if p.thermal == "none" else p.t_bulk)     # Eq. 2
    if not c > 0.0:
        raise ValueError("thermal interference: backlash c_j <= 0 (Eq. 2), c_j = %r" % c)
    l_ref, w_ref = _refs(p, scaled)
    d = np.zeros(_NSCAL + 2 * p.z)
    v = dict(ncalls=0.0, err=0.0, z=p.z, omega=p.omega, phase0=p.theta_0 - p.alpha,
             l_x=p.l_x, l_y=p.l_y, c=c, k_m=p.k_m, c_m=p.c_m, r_b=p.r_b,
             k_p1=p.k_p1, c_p1=p.c_p1, m_1=p.m_1, k_p2=p.k_p2, c_p2=p.c_p2, m_2=p.m_2,
             grav=p.grav, k_t1=p.k_t1, c_t1=p.c_t1, k_t2=p.k_t2, c_t2=p.c_t2,
             j_1=p.j_1, j_m=p.j_m, j_2=p.j_2, j_l=p.j_l, t_d=p.t_d, t_l=p.t_l,
             l_ref=l_ref, w_ref=w_ref,
             coupled=1.0 if p.thermal == "coupled" else 0.0, c0=p.c0, th_coef=p.th_coef,
             t_bulk=p.t_bulk, b=p.b, eta_hertz=p.eta_hertz, hertz=p.hertz, grc=p.grc,
             uf=p.u_flash * p.f_m, R=p.R, cos_a=p.cos_a, r_lo=p.r_lo, r_hi=p.r_hi)
    for k, x in v.items():
        d[_I[k]] = x
    ang = p.two_pi_j_over_z                       # 2 pi j / Z, j = 1..Z (Eq. 8)
    d[_NSCAL:_NSCAL + p.z] = np.cos(ang)
    d[_NSCAL + p.z:] = np.sin(ang)
    return d


# --------------------------------------------------------------------------------------------
# Compiled pieces
# --------------------------------------------------------------------------------------------
@nb.njit(cache=True)
def _contact_radius(delta, R, cos_a, r_lo, r_hi):
    """Eq. 13 for both splines (one contact point per tooth pair, docs/model.md s.6), held on the
    active profile [r_lo, r_hi]."""
    return min(max(math.sqrt(delta * delta + R * R - 2.0 * R * delta * cos_a), r_lo), r_hi)


@nb.njit(cache=True)
def _h(f, A, Req, dn, ddn, sigma, k_m, c_m, b, eta, hertz, c0, th, tb):
    """Residual f - G(f) of the coupled tooth force (bisection fallback)."""
    fe = abs(f) / b
    Tf = 0.0
    if fe > 0.0:
        Tf = A * fe / math.sqrt(eta * math.sqrt(hertz * fe * Req))       # Eqs. 3-4
    return f - (k_m * (dn - sigma * (c0 - th * (tb + Tf))) + c_m * ddn)


@nb.njit(cache=True)
def _coupled_force(d, dn, ddn, sp, cp, X1, Y1, x2, y2, vx1, vy1, vx2, vy2):
    """Thermally coupled tooth force of one tooth in contact (docs/model.md s.6; Eqs. 1-7, 12-17).

    F = k_m (dn - sigma c(F)) + c_m ddn, c = c0 - th_coef (T_M + T_f(|F|)). Fixed-point
    iteration from the T_f = 0 force F0 until |F_{n+1} - F_n| <= 4.5e-16 |F_{n+1}| (2 ulp; the
    map contracts with factor ~1e-3), at most 60 iterations; then bisection on the bracket
    [F0, F0 + sigma aK M^(3/4)] (as the oracle's brentq fallback) to 4 eps. Returns F, or NaN
    with d[err] = 1 if the backlash closes (thermal interference)."""
    omega = d[_OMEGA]
    R = d[_R]
    cos_a = d[_COS_A]
    r_lo = d[_R_LO]
    r_hi = d[_R_HI]
    r_b = d[_R_B]
    # Eq. 12 (simplified, MODEL s.6)
    d1 = X1 * cp + Y1 * sp
    d2 = x2 * cp + y2 * sp
    rc1 = _contact_radius(d1, R, cos_a, r_lo, r_hi)
    rc2 = _contact_radius(d2, R, cos_a, r_lo, r_hi)
    Rc1 = rc1 * math.sin(math.acos(r_b / rc1))                         # Eqs. 5-6
    Rc2 = rc2 * math.sin(math.acos(r_b / rc2))
    v1 = omega * rc1 * cos_a                                             # Eq. 7
    v2 = omega * rc2 * cos_a
    Req = Rc1 * Rc2 / (Rc1 + Rc2)
    grc = d[_GRC]
    S = math.sqrt(grc * abs(v1)) + math.sqrt(grc * abs(v2))
    A = d[_UF] * abs(v1 - v2) / S if S > 0.0 else 0.0
    k_m = d[_K_M]
    c_m = d[_C_M]
    b = d[_B]
    eta = d[_ETA_HERTZ]
    hertz = d[_HERTZ]
    c0 = d[_C0]
    th = d[_TH_COEF]
    tb = d[_T_BULK]
    sigma = 1.0 if dn > 0.0 else -1.0
    Fc = k_m * (dn - sigma * (c0 - th * tb)) + c_m * ddn                  # F0 (T_f = 0)
    F0 = Fc
    done = False
    for _ in range(_FP_MAXIT):
        fe = abs(Fc) / b
        Tf = 0.0
        if fe > 0.0:
            B = eta * math.sqrt(hertz * fe * Req)                            # Eq. 4
            Tf = A * fe / math.sqrt(B)                                       # Eq. 3
        cv = c0 - th * (tb + Tf)                                             # Eqs. 1-2
        if cv <= 0.0:
            d[_ERR] = 1.0
            return math.nan
        Fn = k_m * (dn - sigma * cv) + c_m * ddn                             # Eqs. 15-17
        done = abs(Fn - Fc) <= _FP_RTOL * abs(Fn) + _FP_ATOL
        Fc = Fn
        if done:
            break
    if done:
        return Fc
    # fallback (|F| ~ 1e-9 N or less): bisection on h(f) = f - G(f)
    fe1 = 1.0 / b
    aK = k_m * th * A * fe1 / math.sqrt(eta * math.sqrt(hertz * fe1 * Req))
    M = max(2.0 * abs(F0), (2.0 * aK) ** 4)
    F1 = F0 + sigma * aK * M ** 0.75
    lo = min(F0, F1)
    hi = max(F0, F1)
    args = (A, Req, dn, ddn, sigma, k_m, c_m, b, eta, hertz, c0, th, tb)
    hlo = _h(lo, *args)
    if hlo == 0.0:
        return lo
    for _ in range(2000):
        mid = 0.5 * (lo + hi)
        if hi - lo <= 4.0 * 2.220446049250313e-16 * abs(mid) or mid == lo or mid == hi:
            break
        hm = _h(mid, *args)
        if hm == 0.0:
            return mid
        if (hm > 0.0) == (hlo > 0.0):
            lo = mid
            hlo = hm
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _rhs_py(tau, u, du, d):
    """Right-hand side in the scaled variables of Eq. 25 (SI when l_ref = w_ref = 1):
    u[0:7] = q / l, u[7:14] = q' / (l w), derivative with respect to tau = w t."""
    d[_NCALLS] += 1.0
    l = d[_L_REF]
    w = d[_W_REF]
    lw = l * w
    t = tau / w
    x1 = u[0] * l
    y1 = u[1] * l
    x2 = u[2] * l
    y2 = u[3] * l
    D1 = u[4] * l
    D2 = u[5] * l
    D3 = u[6] * l
    vx1 = u[7] * lw
    vy1 = u[8] * lw
    vx2 = u[9] * lw
    vy2 = u[10] * lw
    dD1 = u[11] * lw
    dD2 = u[12] * lw
    dD3 = u[13] * lw

    omega = d[_OMEGA]
    c = d[_C]
    k_m = d[_K_M]
    c_m = d[_C_M]
    r_b = d[_R_B]
    z = int(d[_Z])
    X1 = x1 + d[_L_X]
    Y1 = y1 + d[_L_Y]
    ex = X1 - x2
    ey = Y1 - y2
    dvx = vx1 - vx2
    dvy = vy1 - vy2
    a = omega * t + d[_PHASE0]                    # phi_j = 2 pi j/Z + a  (Eqs. 8-9)
    sa = math.sin(a)
    ca = math.cos(a)
    coupled = d[_COUPLED] != 0.0
    sumF = 0.0
    sumFs = 0.0
    sumFc = 0.0
    for j in range(z):
        cj = d[_NSCAL + j]
        sj = d[_NSCAL + z + j]
        sp = sa * cj + ca * sj                    # sin(a + 2 pi j/Z)
        cp = ca * cj - sa * sj                    # cos(a + 2 pi j/Z)
        dn = ex * sp - ey * cp + D2                                        # Eq. 11
        if dn > c:
            delta = dn - c
        elif dn < -c:
            delta = dn + c
        else:
            continue                              # dead zone: F_j = 0 (Eqs. 15-17)
        ddn = dvx * sp - dvy * cp + dD2 + omega * (ex * cp + ey * sp)      # d/dt Eq. 11
        if coupled:
            F = _coupled_force(d, dn, ddn, sp, cp, X1, Y1, x2, y2, vx1, vy1, vx2, vy2)
        else:
            F = k_m * delta + c_m * ddn                                    # Eqs. 15-17
        sumF += F
        sumFs += F * sp
        sumFc += F * cp
    Tm = r_b * sumF                                                        # Eq. 22
    Fx1 = -sumFs                                                           # MODEL s.4
    Fy1 = sumFc

    S1 = (d[_K_T1] * D1 + d[_C_T1] * dD1) / r_b
    S2 = (d[_K_T2] * D3 + d[_C_T2] * dD3) / r_b
    a1 = (Tm - S1) / d[_J_1]                     # th1''
    aM = (d[_T_D] + S1) / d[_J_M]                # thM''
    a2 = (-Tm - S2) / d[_J_2]                    # th2''
    aL = (S2 - d[_T_L]) / d[_J_L]                # thL''
    grav = d[_GRAV]
    s_a = 1.0 / (lw * w)                         # d(q'/(l w))/dtau = q''/(l w^2); 1 in SI
    for i in range(7):
        du[i] = u[7 + i]                         # d(q/l)/dtau = q'/(l w) = u[7+i]
    du[7] = ((Fx1 - d[_C_P1] * vx1 - d[_K_P1] * x1) / d[_M_1]) * s_a
    du[8] = ((Fy1 - d[_C_P1] * vy1 - d[_K_P1] * y1) / d[_M_1] - grav) * s_a
    du[9] = ((-Fx1 - d[_C_P2] * vx2 - d[_K_P2] * x2) / d[_M_2]) * s_a
    du[10] = ((-Fy1 - d[_C_P2] * vy2 - d[_K_P2] * y2) / d[_M_2] - grav) * s_a
    du[11] = (r_b * (a1 - aM)) * s_a             # D1'' = r_b (th1'' - thM'')  (Eq. 24)
    du[12] = (r_b * (a2 - a1)) * s_a             # D2'' = r_b (th2'' - th1'')
    du[13] = (r_b * (a2 - aL)) * s_a             # D3'' = r_b (th2'' - thL'')


# --------------------------------------------------------------------------------------------
# The fast right-hand side (every thermal level but 'coupled'): the same model with every
# constant folded into the scaled units of Eq. 25 at packing time, and the per-tooth trigonometry
# turned into two dot products. With a = omega t + theta_0 - alpha, c_j = cos(2 pi j/Z),
# s_j = sin(2 pi j/Z) (precomputed), e = (X1 - x2, Y1 - y2) in units of l:
#   dn_j / l        = P c_j + Q s_j + D2/l + e_j/l,     P = e_x sin a - e_y cos a,
#                                                      Q = e_x cos a + e_y sin a      (Eq. 11)
#   ddn_j / (l w)   = R c_j + T s_j + D2'/(l w),        R = dv_x sin a - dv_y cos a + (omega/w) Q,
#                                                      T = dv_x cos a + dv_y sin a - (omega/w) P
#   F_j = k_m l f_j,  f_j = delta_j / l + (c_m w / k_m) ddn_j / (l w)                (Eqs. 15-17)
#   sum F_j sin phi_j = k_m l (sin a A + cos a B), sum F_j cos phi_j = k_m l (cos a A - sin a B),
#   A = sum f_j c_j, B = sum f_j s_j, T_m = r_b k_m l S, S = sum f_j                (Eqs. 19-22)
# so a tooth costs two multiply-adds for dn_j, a max and a min and five more, without a branch
# (the loop vectorises); one sin and one cos per call; no allocation. The equations of motion are then linear in the scaled states
# with precomputed coefficients (derived from Eqs. 23-24 as in the docstring of oracle.rhs).
# --------------------------------------------------------------------------------------------
_FNAMES = ("ncalls", "z", "wr", "phase0", "lxh", "lyh", "ch", "gam", "fscale", "rb",
           "g1", "cv1", "kp1", "g2", "cv2", "kp2", "gy",
           "aS1", "a41", "a111", "e1", "aS2", "a42", "a112", "a62", "a132",
           "aS3", "a63", "a133", "e3")
_F = {n: i for i, n in enumerate(_FNAMES)}
_NF = len(_FNAMES)
(_FN, _FZ, _WR, _PH0, _LXH, _LYH, _CH, _GAM, _FSC, _FRB, _G1, _CV1, _KP1, _G2, _CV2, _KP2, _GY,
 _AS1, _A41, _A111, _E1, _AS2, _A42, _A112, _A62, _A132, _AS3, _A63, _A133, _E3) = range(_NF)


def _pack_fast(params, scaled):
    """The `data` array of the fast RHS: folded scalars, then c_j, s_j and e_j / l (j = 1..Z)."""
    p = oracle.prepare(params)
    c = p.c0 - p.th_coef * (0.0 if p.thermal == "none" else p.t_bulk)     # Eq. 2
    if not c > 0.0:
        raise ValueError("thermal interference: backlash c_j <= 0 (Eq. 2), c_j = %r" % c)
    if not p.k_m > 0.0:
        raise ValueError("the peer needs k_m > 0 (it does not compute Eq. 18)")
    l, w = _refs(p, scaled)
    w2 = w * w
    iJ1, iJ2, iJM, iJL = 1.0 / p.j_1, 1.0 / p.j_2, 1.0 / p.j_m, 1.0 / p.j_l
    kS = p.r_b * p.r_b * p.k_m / w2            # T_m r_b / (l w^2) per unit S
    v = dict(ncalls=0.0, z=p.z, wr=p.omega / w, phase0=p.theta_0 - p.alpha,
             lxh=p.l_x / l, lyh=p.l_y / l, ch=c / l, gam=p.c_m * w / p.k_m, fscale=p.k_m * l,
             rb=p.r_b, g1=p.k_m / (p.m_1 * w2), cv1=p.c_p1 / (p.m_1 * w),
             kp1=p.k_p1 / (p.m_1 * w2), g2=p.k_m / (p.m_2 * w2), cv2=p.c_p2 / (p.m_2 * w),
             kp2=p.k_p2 / (p.m_2 * w2), gy=p.grav / (l * w2),
             # D1'' = r_b [T_m/J1 - S1 (1/J1 + 1/JM) - T_d/JM],     S1 = (k_t1 D1 + c_t1 D1')/r_b
             aS1=kS * iJ1, a41=p.k_t1 * (iJ1 + iJM) / w2, a111=p.c_t1 * (iJ1 + iJM) / w,
             e1=p.r_b * p.t_d * iJM / (l * w2),
             # D2'' = r_b [-T_m (1/J1 + 1/J2) + S1/J1 - S2/J2]
             aS2=kS * (iJ1 + iJ2), a42=p.k_t1 * iJ1 / w2, a112=p.c_t1 * iJ1 / w,
             a62=p.k_t2 * iJ2 / w2, a132=p.c_t2 * iJ2 / w,
             # D3'' = r_b [-T_m/J2 - S2 (1/J2 + 1/JL) + T_L/JL],    S2 = (k_t2 D3 + c_t2 D3')/r_b
             aS3=kS * iJ2, a63=p.k_t2 * (iJ2 + iJL) / w2, a133=p.c_t2 * (iJ2 + iJL) / w,
             e3=p.r_b * p.t_l * iJL / (l * w2))
    d = np.zeros(_NF + 3 * p.z)
    for k, x in v.items():
        d[_F[k]] = x
    d[_NF:_NF + p.z] = np.cos(p.two_pi_j_over_z)
    d[_NF + p.z:_NF + 2 * p.z] = np.sin(p.two_pi_j_over_z)
    d[_NF + 2 * p.z:] = p.e / l                  # spacing errors (docs/model.md s.11)
    return d


@nb.njit(inline="always", fastmath=True, error_model="numpy")
def _rhs_fast(tau, u, du, d):
    """Right-hand side in the scaled states u = (q/l, q'/(l w)) and time tau = w t (Eq. 25)."""
    z = int(d[_FZ])
    a = d[_WR] * tau + d[_PH0]
    sa = math.sin(a)
    ca = math.cos(a)
    ex = u[0] + d[_LXH] - u[2]
    ey = u[1] + d[_LYH] - u[3]
    dvx = u[7] - u[9]
    dvy = u[8] - u[10]
    wr = d[_WR]
    P = ex * sa - ey * ca
    Q = ex * ca + ey * sa
    R = dvx * sa - dvy * ca + wr * Q
    T = dvx * ca + dvy * sa - wr * P
    D2 = u[5]
    dD2 = u[12]
    ch = d[_CH]
    gam = d[_GAM]
    S = 0.0
    A = 0.0
    B = 0.0
    for j in range(z):
        cj = d[_NF + j]
        sj = d[_NF + z + j]
        dz = P * cj + Q * sj + D2 + d[_NF + 2 * z + j]      # the dead zone sees dn_j + e_j
        f = max(dz - ch, 0.0) + min(dz + ch, 0.0)           # delta_j (0 in the dead zone)
        g = gam * (R * cj + T * sj + dD2)
        f = f + g if f != 0.0 else 0.0                       # branch-free: 25 % faster
        S += f
        A += f * cj
        B += f * sj
    Fs = sa * A + ca * B                            # sum F_j sin phi_j / (k_m l)
    Fc = ca * A - sa * B                            # sum F_j cos phi_j / (k_m l)
    for i in range(7):
        du[i] = u[7 + i]
    du[7] = -d[_G1] * Fs - d[_CV1] * u[7] - d[_KP1] * u[0]
    du[8] = d[_G1] * Fc - d[_CV1] * u[8] - d[_KP1] * u[1] - d[_GY]
    du[9] = d[_G2] * Fs - d[_CV2] * u[9] - d[_KP2] * u[2]
    du[10] = -d[_G2] * Fc - d[_CV2] * u[10] - d[_KP2] * u[3] - d[_GY]
    du[11] = d[_AS1] * S - d[_A41] * u[4] - d[_A111] * u[11] - d[_E1]
    du[12] = -d[_AS2] * S + d[_A42] * u[4] + d[_A112] * u[11] - d[_A62] * u[6] - d[_A132] * u[13]
    du[13] = -d[_AS3] * S - d[_A63] * u[6] - d[_A133] * u[13] + d[_E3]


def _rhs_fast_counted(tau, u, du, d):
    """The fast RHS counting its calls in d[0] (make_rhs's cfunc; _frozen's does not count)."""
    d[_FN] += 1.0
    _rhs_fast(tau, u, du, d)


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def _forces(d, tau, u):
    """T_m and F_j (SI) at the outputs from the scaled states u (n, 14): the only outputs the race
    compares, formed as the RHS forms them (branch-free and fastmath: 3x faster than with
    branches, within 1e-13 of them)."""
    n = tau.shape[0]
    z = int(d[_FZ])
    F = np.empty((n, z))
    Tm = np.empty(n)
    wr = d[_WR]
    ch = d[_CH]
    gam = d[_GAM]
    fs = d[_FSC]
    c = d[_NF:_NF + z]
    s = d[_NF + z:_NF + 2 * z]
    e = d[_NF + 2 * z:_NF + 3 * z]
    for k in range(n):
        a = wr * tau[k] + d[_PH0]
        sa = math.sin(a)
        ca = math.cos(a)
        ex = u[k, 0] + d[_LXH] - u[k, 2]
        ey = u[k, 1] + d[_LYH] - u[k, 3]
        dvx = u[k, 7] - u[k, 9]
        dvy = u[k, 8] - u[k, 10]
        P = ex * sa - ey * ca
        Q = ex * ca + ey * sa
        R = dvx * sa - dvy * ca + wr * Q
        T = dvx * ca + dvy * sa - wr * P
        D2 = u[k, 5]
        dD2 = u[k, 12]
        S = 0.0
        for j in range(z):
            dz = P * c[j] + Q * s[j] + D2 + e[j]
            f = max(dz - ch, 0.0) + min(dz + ch, 0.0)
            g = gam * (R * c[j] + T * s[j] + dD2)
            f = fs * (f + g) if f != 0.0 else 0.0
            F[k, j] = f
            S += f
        Tm[k] = d[_FRB] * S
    return Tm, F


_CFUNC = {}
COMPILE_SECONDS = []      # wall time of each numba compilation (or cache load) of an RHS


def _compiled(kind="fast"):
    """The RHS compiled once per process (numba cfunc with numbalsoda's signature; numba's cache
    in bench/__pycache__ keeps the machine code for the next process): 'fast' (every thermal
    level but coupled) or 'general' (the coupled level; the reference form)."""
    if kind not in _CFUNC:
        t0 = time.perf_counter()
        fast = kind == "fast"        # fastmath: 10 % faster, within 1e-12 of the oracle
        _CFUNC[kind] = cfunc(lsoda_sig, nopython=True, cache=True, error_model="numpy",
                             fastmath=fast)(_rhs_fast_counted if fast else _rhs_py)
        COMPILE_SECONDS.append(time.perf_counter() - t0)
    return _CFUNC[kind]


def compile_all():
    """Compiles both right-hand sides and the forces into numba's cache (bench/__pycache__), so
    that later processes load them (`scripts/setup.sh --tests` runs it once: each test worker
    would otherwise compile them, about 6 s of CPU)."""
    _compiled("fast"), _compiled("general")
    Setup(load_case({"k_m": 2.3e5})).forces(np.zeros(2), np.zeros((2, 14)))


def _refs(p, scaled):
    """(l, w) of Eq. 25: c0 or l_ref, the shaft speed or w_ref; (1, 1) unscaled."""
    if not scaled:
        return 1.0, 1.0
    l_ref = float(p.case.get("l_ref", 0.0) or 0.0) or p.c0
    w_ref = float(p.case.get("w_ref", 0.0) or 0.0) or p.omega
    if not w_ref > 0.0:
        raise ValueError("scaled integration needs w_ref > 0 (shaft speed is 0): set w_ref")
    return l_ref, w_ref


def make_rhs(params, scaled=True, kind=None):
    """numbalsoda-compatible compiled RHS for a case.

    params: a dict of case fields (as tests/oracle.py's `prepare` takes; see load_case for the
    defaults) or an oracle.Prepared. Returns (rhs, data): `rhs` is a numba cfunc with
    numbalsoda's lsoda_sig (pass rhs.address to numbalsoda.lsoda), `data` the float64 parameter
    array to pass as numbalsoda's `data` (data[0] counts RHS calls). scaled=True: the RHS is in
    the scaled states and time of Eq. 25 (l = c0 or l_ref, w = shaft speed or w_ref);
    scaled=False: plain SI, y' = f(t, y) as oracle.rhs. kind: 'fast' (not for the coupled
    level), 'general' (every level), None: 'fast' unless the case is coupled. Each kind is
    compiled once per process; the parameters only change `data`."""
    p = oracle.prepare(params)
    if kind is None:
        kind = "general" if p.thermal == "coupled" else "fast"
    if kind == "fast":
        if p.thermal == "coupled":
            raise ValueError("the fast RHS has no coupled thermal level: kind='general'")
        return _compiled("fast"), _pack_fast(p, scaled)
    if np.any(p.e != 0.0):
        raise ValueError("the general RHS has no spacing errors: kind='fast'")
    return _compiled("general"), _pack(p, scaled)


def _driver(method):
    """numbalsoda.lsoda or numbalsoda.dop853, from numbalsoda's driver modules (driver.py,
    driver_dop853.py) loaded on their own: `import numbalsoda` also compiles its solve_ivp,
    unused here, for about 9 s of CPU."""
    if method not in _DRIVERS:
        import importlib.util
        name = {"lsoda": "driver", "dop853": "driver_dop853"}[method]
        spec = importlib.util.find_spec("numbalsoda")
        if spec is None:
            raise ImportError("numbalsoda is not installed")
        spec = importlib.util.spec_from_file_location(
            f"numbalsoda_{name}", Path(spec.origin).parent / f"{name}.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        _DRIVERS[method] = getattr(mod, method)
    return _DRIVERS[method]


_DRIVERS = {}


class Setup:
    """A case made ready to solve: the compiled RHS, its `data`, the scales of Eq. 25."""

    def __init__(self, params, scaled=True, kind=None):
        p = oracle.prepare(params)
        self.fn, self.data = make_rhs(p, scaled, kind)
        self.kind = "fast" if self.data.shape[0] == _NF + 3 * p.z else "general"
        self.l, self.w = _refs(p, scaled)
        self.scale = np.r_[np.full(7, self.l), np.full(7, self.l * self.w)]
        self._frozen = None

    def integrate(self, y0, t_eval, rtol, atol, method="dop853", mxstep=1_000_000, frozen=False):
        """Scaled states at t_eval (tau = w t_eval) from y0 (SI): (u, success). frozen: on the
        case's frozen RHS (_frozen; the fast kind only; it does not count calls in data[0])."""
        if method not in ("lsoda", "dop853"):
            raise ValueError(f"method {method!r}: 'lsoda' or 'dop853'")
        if frozen and self._frozen is None:
            if self.kind != "fast":
                raise ValueError("the frozen RHS is the fast one (not the coupled level)")
            self._frozen = _frozen(self.data)
        self.data[0] = 0.0
        u, ok = _driver(method)((self._frozen if frozen else self.fn).address,
                                np.asarray(y0, float) / self.scale,
                                np.asarray(t_eval, float) * self.w, data=self.data,
                                rtol=float(rtol), atol=float(atol), mxstep=int(mxstep))
        if self.kind == "general" and self.data[_ERR] != 0.0:
            raise ValueError("thermal interference: backlash c_j <= 0 (Eq. 2) during the solve")
        return u, bool(ok)

    def forces(self, t_eval, u):
        """(T_m, F) in SI at t_eval from the scaled states u (the fast RHS's kind only)."""
        return _forces(self.data, np.asarray(t_eval, float) * self.w, u)

    def run(self, y0, t_eval, rtol, atol, method="dop853", mxstep=1_000_000):
        """(T_m, F, success) at t_eval from y0 (SI): the race's peer, integrate on the frozen RHS
        then forces."""
        u, ok = self.integrate(y0, t_eval, rtol, atol, method, mxstep, frozen=True)
        return (*self.forces(t_eval, u), ok)


def _frozen(data):
    """The fast RHS of one case with its `data` frozen into the machine code: numba compiles a
    closure's array as a constant, so Z, the coefficients and c_j, s_j, e_j are constants the
    compiler folds. 48.5 against 60 ns a call in a loop (paper_lx1e-4); in DOP853 runs,
    CPU medians against make_rhs's cfunc (which also counts calls): paper_lx1e-4 10.07 against
    10.75 ms, physical_z24 46.6 against 50.3 ms. Compiled once per case (0.85 s) into numba's
    cache, keyed by the values of `data`."""
    dc = data.copy()
    dc[_FN] = 0.0

    def rhs(tau, u, du, _):
        _rhs_fast(tau, u, du, dc)
    return cfunc(lsoda_sig, nopython=True, error_model="numpy", fastmath=True, cache=True)(rhs)


def rhs_eval(params, t, y, scaled=False, kind=None):
    """dy/dt of the compiled RHS at (t, y), called through ctypes (SI unless scaled)."""
    fn, data = make_rhs(params, scaled=scaled, kind=kind)
    u = np.ascontiguousarray(y, dtype=float).copy()
    du = np.zeros(14)
    P = ctypes.POINTER(ctypes.c_double)
    fn.ctypes(float(t), u.ctypes.data_as(P), du.ctypes.data_as(P), data.ctypes.data_as(P))
    if data.shape[0] == _NSCAL + 2 * len(oracle.prepare(params).e) and data[_ERR] != 0.0:
        raise ValueError("thermal interference: backlash c_j <= 0 (Eq. 2)")
    return du


def solve(params, y0, t_eval, rtol=1e-8, atol=1e-10, mxstep=1_000_000, scaled=True,
          method="lsoda", kind=None):
    """Integrate with numbalsoda's LSODA (method 'lsoda') or DOP853 ('dop853', Hairer's
    explicit Runge-Kutta 8(5,3) with its dense output at t_eval; mxstep is then its budget of
    steps over the whole run). y0 (14, SI) and t_eval (s; t_eval[0] is the start time) as for
    oracle.rhs. atol is on the scaled states of Eq. 25 (atol*l [m] on lengths, atol*l*w [m/s] on
    velocities) when scaled=True, else in SI for every state. mxstep: LSODA's steps allowed
    between two output times.
    Returns (y, success, n_rhs): y of shape (len(t_eval), 14) in SI, the success flag, the
    number of RHS calls (counted in data[0]; includes LSODA's Jacobian difference quotients)."""
    s = Setup(params, scaled, kind)
    u, ok = s.integrate(y0, t_eval, rtol, atol, method, mxstep)
    return u * s.scale, ok, int(s.data[0])
