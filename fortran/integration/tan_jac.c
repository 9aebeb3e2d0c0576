/* CVODE's Jacobian callback (CVLsJacFn) of the variational run. Its frozen-contact Jacobian
 * depends on the time and the run's contact modes (its user data) alone: not on the state,
 * f(state) or CVODE's three work vectors, which this drops before calling the Fortran
 * (spline_variational::tan_jac). N_Vector and SUNMatrix are pointers: void * here. */
int tan_jac(double tau, void *jmat, void *udata);

int tan_jac_cvode(double tau, void *y, void *fy, void *jmat, void *udata, void *tmp1,
                  void *tmp2, void *tmp3)
{
    (void)y; (void)fy; (void)tmp1; (void)tmp2; (void)tmp3;
    return tan_jac(tau, jmat, udata);
}
