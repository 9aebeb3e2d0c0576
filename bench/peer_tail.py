"""The race's peer with a closed-form tail of its own (issue 34): numbalsoda's DOP853 on
bench/numba_peer.py's frozen fast RHS until every tooth is proven to stay in contact on one flank,
then the rest of the run from the eigenpairs of the constant affine system. Written from
docs/model.md alone (it imports neither pyspline nor its core), its proof derived here:

With every tooth on flank s (Eqs. 15-17: s dn_j > c) and Z >= 3, sum_j sin^2 phi_j = sum_j
cos^2 phi_j = Z/2 and sum_j sin phi_j cos phi_j = sum_j sin phi_j = sum_j cos phi_j = 0, so
Eqs. 19-22 give the lateral force on spline 1 -(Z/2) [k_m e + c_m (e' + omega (e_y, -e_x))] and
T_m = r_b Z [k_m (D2 - s c) + c_m D2'] at any angle (e = (X1 - x2, Y1 - y2)): without spacing
errors, ripple, unbalance, angular misalignment or the coupled thermal level, the scaled system
of Eq. 25 is u' = A u + b, time-invariant (`affine_rhs`, tests/test_numba_peer.py holds it to
oracle.rhs). With u* = -A^-1 b, u - u* = Re sum_k v_k c_k exp(lambda_k (tau - tau_0)) and every
Re lambda_k < 0, no mode grows, so for all later times |D2 - D2*| <= sum_k |v_D2,k| |c_k| and
|e - e*| <= sum_k |(v_x1 - v_x2, v_y1 - v_y2)_k| |c_k|. Since |dn_j - D2| <= |e| (Eq. 11), every
tooth stays on flank s for ever if s D2* - c - |e*| exceeds that bound (1 % added for the
round-off of the eigenvectors; near-defective eigenvectors, V^-1 V further than 1e-8 from I, prove
nothing).

The run: DOP853 over one shaft revolution of outputs, then over chunks 1.5x longer each time;
after each chunk the proof is tried at every output of it (the states at the outputs are
DOP853's dense output, at the peer's rtol); from the first output where it holds, the later
outputs are the closed form (at uniform output steps h the real propagator Re(V exp(lambda h)
V^-1) applied in turn, else the modal sum at each time), then T_m and F as numba_peer's forces.
The tail is exact up to its hand-over: on paper_lx1e-4 its F agree with DOP853 at rtol 1e-13
without a tail to 3e-13 of max |F| (tests/test_numba_peer.py holds a shorter scene). Its set-up
(A, the eigenpairs) is inside the race's clock.
"""
import math

import numba as nb
import numpy as np

import numba_peer
import oracle

#: the first chunk of DOP853 in shaft revolutions, and the growth of each next one
CHUNK_REVS, GROWTH = 1.0, 1.5


def affine_rhs(p, s, c):
    """dy/dt (SI) with every tooth on flank s, the mesh a linear isotropic spring; y (14, n)."""
    Z, km, cm, w = p.z, p.k_m, p.c_m, p.omega

    def f(y):
        x1, y1, x2, y2, D1, D2, D3 = y[:7]
        vx1, vy1, vx2, vy2, dD1, dD2, dD3 = y[7:]
        ex, ey = x1 + p.l_x - x2, y1 + p.l_y - y2
        dvx, dvy = vx1 - vx2, vy1 - vy2
        Fx1 = -0.5 * Z * (km * ex + cm * (dvx + w * ey))
        Fy1 = -0.5 * Z * (km * ey + cm * (dvy - w * ex))
        Tm = p.r_b * Z * (km * (D2 - s * c) + cm * dD2)
        S1 = (p.k_t1 * D1 + p.c_t1 * dD1) / p.r_b
        S2 = (p.k_t2 * D3 + p.c_t2 * dD3) / p.r_b
        a1, aM = (Tm - S1) / p.j_1, (p.t_d + S1) / p.j_m
        a2, aL = (-Tm - S2) / p.j_2, (S2 - p.t_l) / p.j_l
        return np.vstack([y[7:], (Fx1 - p.c_p1 * vx1 - p.k_p1 * x1) / p.m_1,
                          (Fy1 - p.c_p1 * vy1 - p.k_p1 * y1) / p.m_1 - p.grav,
                          (-Fx1 - p.c_p2 * vx2 - p.k_p2 * x2) / p.m_2,
                          (-Fy1 - p.c_p2 * vy2 - p.k_p2 * y2) / p.m_2 - p.grav,
                          p.r_b * (a1 - aM), p.r_b * (a2 - a1), p.r_b * (a2 - aL)])
    return f


class Flank:
    """The tail on flank s in the scaled units of Eq. 25 (l, w): A, b, u*, the eigenpairs, the
    bound's weights and margin; `ok` False where nothing can be proven."""

    def __init__(self, p, s, c, l, w):
        sc = np.r_[np.full(7, l), np.full(7, l * w)]
        Y = affine_rhs(p, s, c)(np.c_[np.zeros(14), np.eye(14)])    # b, then b + A e_i
        self.A = (Y[:, 1:] - Y[:, :1]) * sc[None, :] / sc[:, None] / w
        self.b = Y[:, 0] / sc / w
        self.ok = False
        try:                                  # no fixed point (e.g. no support): nothing proven
            self.ustar = np.linalg.solve(self.A, -self.b)
            self.lam, self.V = np.linalg.eig(self.A)
            self.Vi = np.linalg.inv(self.V)
        except np.linalg.LinAlgError:
            return
        V, u = self.V, self.ustar
        self.weight = np.abs(V[5]) + np.hypot(np.abs(V[0] - V[2]), np.abs(V[1] - V[3]))
        self.margin = s * u[5] - c / l - math.hypot(u[0] + p.l_x / l - u[2],
                                                    u[1] + p.l_y / l - u[3])
        self.ok = bool(self.lam.real.max() < 0.0 and self.margin > 0.0
                       and np.abs(self.Vi @ V - np.eye(14)).max() < 1e-8)

    def proven(self, U):
        """The first row of U (scaled states) from which every tooth stays on the flank, or -1."""
        bound = np.abs((U - self.ustar) @ self.Vi.T) @ self.weight
        good = np.flatnonzero(1.01 * bound < self.margin)
        return int(good[0]) if good.size else -1

    def states(self, u0, dtau):
        """Scaled states at tau_0 + dtau (dtau > 0, increasing) from u0 at tau_0."""
        h = dtau[0]
        if np.allclose(np.diff(dtau), h, rtol=1e-12, atol=0.0):
            return _propagate(((self.V * np.exp(self.lam * h)) @ self.Vi).real, self.ustar,
                              u0, len(dtau))
        X = np.exp(np.outer(dtau, self.lam)) * (self.Vi @ (u0 - self.ustar))
        return self.ustar + X.real @ self.V.T.real - X.imag @ self.V.T.imag


@nb.njit(cache=True, fastmath=True)
def _propagate(M, ustar, u0, n):
    """ustar + M^k (u0 - ustar), k = 1..n (loops: 4x faster than numba's M @ d)."""
    out = np.empty((n, 14))
    d = u0 - ustar
    e = np.empty(14)
    for k in range(n):
        for i in range(14):
            acc = 0.0
            for j in range(14):
                acc += M[i, j] * d[j]
            e[i] = acc
        for i in range(14):
            d[i] = e[i]
            out[k, i] = ustar[i] + e[i]
    return out


class TailPeer:
    """numba_peer.Setup's DOP853 run (frozen RHS) with the closed-form tail: .run as Setup.run;
    .tail_t the time the tail began (-1: not used). `able` False for what the tail does not
    cover (Z < 3, coupled thermal level, spacing errors, ripple, unbalance, angular
    misalignment): DOP853 then runs to the end."""

    def __init__(self, params):
        p = oracle.prepare(params)
        self.setup = numba_peer.Setup(p)
        self.setup.integrate(np.zeros(14), np.array([0.0, 1e-6]), 1e-6, 1e-8, frozen=True)
        self.p, self.w = p, self.setup.w
        self.c = p.c0 - p.th_coef * (0.0 if p.thermal == "none" else p.t_bulk)     # Eq. 2
        self.able = (p.z >= 3 and p.thermal != "coupled" and not np.any(p.e != 0.0)
                     and not any(np.any(np.asarray(params.get(k, 0.0), float) != 0.0)
                                 for k in ("ripple_amp", "unbalance", "gamma_x", "gamma_y")))
        self.dop = numba_peer._driver("dop853")
        self.tail_t = -1.0
        _propagate(np.eye(14), np.zeros(14), np.zeros(14), 1)           # compile

    def integrate(self, y0, t_eval, rtol, atol, mxstep=10**9):
        """(u scaled at t_eval from y0 in SI, success); sets tail_t."""
        tau = np.asarray(t_eval, float) * self.w
        out = np.empty((len(tau), 14))
        u0, i = np.asarray(y0, float) / self.setup.scale, 0
        chunk = 2.0 * math.pi * CHUNK_REVS * self.w / self.p.omega
        flanks, self.tail_t = {}, -1.0
        while True:
            j = len(tau)
            if self.able:
                j = min(max(int(np.searchsorted(tau, tau[i] + chunk, "right")), i + 2), j)
            u, ok = self.dop(self.setup._frozen.address, u0, tau[i:j], data=self.setup.data,
                             rtol=rtol, atol=atol, mxstep=mxstep)
            out[i:j] = u
            if not ok or j == len(tau):
                return out, bool(ok)
            s = -1.0 if u[-1, 5] < 0.0 else 1.0
            if s not in flanks:
                flanks[s] = Flank(self.p, s, self.c, self.setup.l, self.w)
            k = flanks[s].proven(u) if flanks[s].ok else -1
            if k >= 0:
                k += i
                out[k + 1:] = flanks[s].states(out[k], tau[k + 1:] - tau[k])
                self.tail_t = tau[k] / self.w
                return out, True
            u0, i, chunk = out[j - 1].copy(), j - 1, chunk * GROWTH

    def run(self, y0, t_eval, rtol, atol, method="dop853", mxstep=10**9):
        """(T_m, F, success) at t_eval: DOP853 (only) to the hand-over, then the tail."""
        if method != "dop853":
            raise ValueError("the tailed peer runs DOP853")
        u, ok = self.integrate(y0, t_eval, rtol, atol, mxstep)
        return (*self.setup.forces(t_eval, u), ok)
