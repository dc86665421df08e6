/* apexseal_dispatch.c: mode table and dispatch over the generated mode functions.
 * Rendered by apexseal from templates/apexseal_dispatch.in.c; do not edit (run `apexseal generate`).
 * Input hash: {{ input_hash }}.
 */
#include "apexseal_model.h"
{% for header in casadi_headers %}
#include "{{ header }}"
{% endfor %}

/* largest work arrays of the mode functions */
#define APEXSEAL_MODE_SZ_ARG {{ work.sz_arg }}
#define APEXSEAL_MODE_SZ_RES {{ work.sz_res }}
#define APEXSEAL_MODE_SZ_IW {{ work.sz_iw }}
#define APEXSEAL_MODE_SZ_W {{ work.sz_w }}

const apexseal_mode_info apexseal_modes[APEXSEAL_NMODES] = {
{% for m in modes %}
  {"{{ m.label }}", "{{ m.function }}", { {{ m.closed|join(", ") }} }},
{% endfor %}
};

int apexseal_mode_index(const double* g) {
  int k, i, match;
  for (k = 0; k < APEXSEAL_NMODES; ++k) {
    match = 1;
    for (i = 0; i < APEXSEAL_NG; ++i) {
      if ((g[i] < 0) != (apexseal_modes[k].closed[i] != 0)) {
        match = 0;
        break;
      }
    }
    if (match) return k;
  }
  return -1;
}

int apexseal_mode_rhs(int mode, double theta, const double* x, const double* p, const double* u, double* xdot) {
  const casadi_real* arg[APEXSEAL_MODE_SZ_ARG + 4];
  casadi_real* res[APEXSEAL_MODE_SZ_RES + 1];
  casadi_int iw[APEXSEAL_MODE_SZ_IW + 1];
  casadi_real w[APEXSEAL_MODE_SZ_W + 1];
  arg[0] = &theta;
  arg[1] = x;
  arg[2] = p;
  arg[3] = u;
  res[0] = xdot;
  switch (mode) {
{% for m in modes %}
    case {{ m.index }}: return {{ m.function }}(arg, res, iw, w, 0);
{% endfor %}
    default: return -1;
  }
}
