/* apexseal_model.c: the generation record compiled into the model library, and the loop that evaluates the
 * model's outputs and guards at many samples in one call.
 * Rendered by apexseal from templates/apexseal_model.in.c; do not edit (run `apexseal generate`).
 * Effects: all.
 */
#include <stdlib.h>

#include "apexseal_model.h"
#include "casadi_model.h"

/* The manifest's input hash: the loader refuses a library whose hash is not the one of the manifest it trusts. */
const char* apexseal_model_input_hash(void) { return APEXSEAL_INPUT_HASH; }

/* The named outputs y (the Function outputs) and the guards g (the Function guards) at n samples, sample-major:
 * theta[n], x[n][APEXSEAL_NX], a[n][APEXSEAL_NG] (the activations), p (shared, p_stride 0: p[APEXSEAL_NP]; or per
 * sample, p_stride APEXSEAL_NP: p[n][APEXSEAL_NP], a scene's schedule), u[n][APEXSEAL_NU] in; y[n][APEXSEAL_NY] and g[n][APEXSEAL_NG] out (y NULL: the guards only; then a is not read). The same
 * compiled Functions as their CasADi externals, called here in a loop: CasADi's map of an external costs about
 * ten times the evaluation per sample (runtime/results/sampled.py). Returns 0; 1 when a Function failed, 2
 * when out of memory. */
int apexseal_outputs_block(const casadi_real* theta, const casadi_real* x, const casadi_real* a,
                           const casadi_real* p, int p_stride, const casadi_real* u, int n, casadi_real* y,
                           casadi_real* g) {
  casadi_int n_arg, n_res, n_iw, n_w, n_arg2, n_res2, n_iw2, n_w2;
  outputs_work(&n_arg, &n_res, &n_iw, &n_w);
  guards_work(&n_arg2, &n_res2, &n_iw2, &n_w2);
  if (n_arg2 > n_arg) n_arg = n_arg2;
  if (n_res2 > n_res) n_res = n_res2;
  if (n_iw2 > n_iw) n_iw = n_iw2;
  if (n_w2 > n_w) n_w = n_w2;
  const casadi_real** arg = malloc(sizeof(casadi_real*) * (size_t)(n_arg + 1));
  casadi_real** res = malloc(sizeof(casadi_real*) * (size_t)(n_res + 1));
  casadi_int* iw = malloc(sizeof(casadi_int) * (size_t)(n_iw + 1));
  casadi_real* w = malloc(sizeof(casadi_real) * (size_t)(n_w + 1));
  int status = (arg && res && iw && w) ? 0 : 2;
  for (int k = 0; k < n && !status; k++) {
    const casadi_real* xk = x + (size_t)k * APEXSEAL_NX;
    const casadi_real* uk = u + (size_t)k * APEXSEAL_NU;
    const casadi_real* pk = p + (size_t)k * (size_t)p_stride;
    if (y) {
      arg[0] = theta + k; arg[1] = xk; arg[2] = a + (size_t)k * APEXSEAL_NG; arg[3] = pk; arg[4] = uk;
      res[0] = y + (size_t)k * APEXSEAL_NY;
      if (outputs(arg, res, iw, w, 0)) status = 1;
    }
    arg[0] = theta + k; arg[1] = xk; arg[2] = pk; arg[3] = uk;
    res[0] = g + (size_t)k * APEXSEAL_NG;
    if (!status && guards(arg, res, iw, w, 0)) status = 1;
  }
  free(arg); free(res); free(iw); free(w);
  return status;
}
