/* ERKStep's N_VLinearCombination (its stages, solution, error estimate and dense output:
 * z = c_0 X_0 + ... + c_{n-1} X_{n-1}) on the serial vectors of a run, element by element in
 * blocks of 8 (4, 2, 1 at the end) held in registers: SUNDIALS' N_VLinearCombination_Serial
 * makes one pass over z per term, reading and writing z each time. Each element is
 * formed as SUNDIALS forms it, c_0 x_0 then + c_i x_i for i = 1, 2, ..., in that order (c_0 = 1
 * where X_0 is z: 1 x is x), so the result is SUNDIALS' bit for bit; with fewer than 3 terms
 * (N_VScale, N_VLinearSum, which treat some coefficients apart) or z among X_1.. it calls
 * SUNDIALS. No fused multiply-add: the build targets x86-64 without FMA. */
#include <string.h>
#include <nvector/nvector_serial.h>

enum { MAX_TERMS = 16 };

/* two doubles (GCC's vector extension: lane by lane, each an IEEE double operation) */
typedef double pair __attribute__((vector_size(16)));

static inline pair load(const realtype *p)
{
    pair v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* z[j0 .. j0+2nb-1]; nb a constant where it is inlined: the block's sums stay in registers */
static inline __attribute__((always_inline)) void block(int nvec, const realtype *c,
                                                        const realtype *const *x, realtype *zd,
                                                        sunindextype j0, const int nb)
{
    pair acc[4];
    int i, k;
    for (k = 0; k < nb; k++)
        acc[k] = c[0] * load(x[0] + j0 + 2 * k);
    for (i = 1; i < nvec; i++)
        for (k = 0; k < nb; k++)
            acc[k] += c[i] * load(x[i] + j0 + 2 * k);
    memcpy(zd + j0, acc, nb * sizeof acc[0]);
}

static int linear_combination(int nvec, realtype *c, N_Vector *X, N_Vector z)
{
    const realtype *x[MAX_TERMS];
    realtype *zd = NV_DATA_S(z);
    sunindextype n = NV_LENGTH_S(z), j0 = 0;
    int i;
    if (nvec < 3 || nvec > MAX_TERMS)
        return N_VLinearCombination_Serial(nvec, c, X, z);
    for (i = 0; i < nvec; i++) {
        if (i > 0 && X[i] == z)
            return N_VLinearCombination_Serial(nvec, c, X, z);
        x[i] = NV_DATA_S(X[i]);
    }
    for (; j0 + 8 <= n; j0 += 8)
        block(nvec, c, x, zd, j0, 4);
    if (j0 + 4 <= n) {
        block(nvec, c, x, zd, j0, 2);
        j0 += 4;
    }
    if (j0 + 2 <= n) {
        block(nvec, c, x, zd, j0, 1);
        j0 += 2;
    }
    if (j0 < n) {
        realtype a = c[0] * x[0][j0];
        for (i = 1; i < nvec; i++)
            a += c[i] * x[i][j0];
        zd[j0] = a;
    }
    return 0;
}

/* The numbers of a serial vector (a run's state vector and its clones), read directly: SUNDIALS'
 * N_VGetArrayPointer goes through the vector's table of operations, an indirect call before
 * every right-hand side can start (twice a call: with N_VGetArrayPointer_Serial 2.4 % of the
 * CPU samples of a chaos_z24 goal run, perf, against 0.4 % of its instructions). */
realtype *spline_serial_data(N_Vector v)
{
    return NV_DATA_S(v);
}

/* Install it in v's operations (before ERKStep clones its vectors from v). */
int spline_lincomb_by_element(N_Vector v)
{
    if (v == NULL || v->ops == NULL)
        return -1;
    v->ops->nvlinearcombination = linear_combination;
    return 0;
}
