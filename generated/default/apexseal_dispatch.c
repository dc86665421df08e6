/* apexseal_dispatch.c: mode table and dispatch over the generated mode functions.
 * Rendered by apexseal from templates/apexseal_dispatch.in.c; do not edit (run `apexseal generate`).
 * Input hash: 497fba140774964c72fe6489e14434a36f79a8f56993ab6ae13b59ebc6614ca3.
 */
#include "apexseal_model.h"
#include "casadi_model.h"
#include "casadi_modes_0.h"
#include "casadi_modes_1.h"
#include "casadi_modes_2.h"
#include "casadi_modes_3.h"
#include "casadi_modes_4.h"
#include "casadi_modes_5.h"
#include "casadi_modes_6.h"
#include "casadi_modes_7.h"
#include "casadi_modes_8.h"

/* largest work arrays of the mode functions */
#define APEXSEAL_MODE_SZ_ARG 4
#define APEXSEAL_MODE_SZ_RES 1
#define APEXSEAL_MODE_SZ_IW 0
#define APEXSEAL_MODE_SZ_W 70

const apexseal_mode_info apexseal_modes[APEXSEAL_NMODES] = {
  {"q1_h_s", "mode_q1_h_s", { 1, 1, 0, 0, 1, 1 }},
  {"q1_h_s0", "mode_q1_h_s0", { 1, 1, 0, 0, 1, 0 }},
  {"q1_h0_s", "mode_q1_h0_s", { 0, 1, 0, 0, 1, 1 }},
  {"q1_h0_s0", "mode_q1_h0_s0", { 0, 1, 0, 0, 1, 0 }},
  {"n3_h_s", "mode_n3_h_s", { 1, 0, 1, 1, 0, 1 }},
  {"n3_h_s0", "mode_n3_h_s0", { 1, 0, 1, 1, 0, 0 }},
  {"n3_h0_s", "mode_n3_h0_s", { 0, 0, 1, 1, 0, 1 }},
  {"n3_h0_s0", "mode_n3_h0_s0", { 0, 0, 1, 1, 0, 0 }},
  {"p1_h_s", "mode_p1_h_s", { 1, 1, 0, 0, 0, 1 }},
  {"p1_h_s0", "mode_p1_h_s0", { 1, 1, 0, 0, 0, 0 }},
  {"p1_h0_s", "mode_p1_h0_s", { 0, 1, 0, 0, 0, 1 }},
  {"p1_h0_s0", "mode_p1_h0_s0", { 0, 1, 0, 0, 0, 0 }},
  {"n2_h_s", "mode_n2_h_s", { 1, 0, 1, 0, 0, 1 }},
  {"n2_h_s0", "mode_n2_h_s0", { 1, 0, 1, 0, 0, 0 }},
  {"n2_h0_s", "mode_n2_h0_s", { 0, 0, 1, 0, 0, 1 }},
  {"n2_h0_s0", "mode_n2_h0_s0", { 0, 0, 1, 0, 0, 0 }},
  {"p3_h_s", "mode_p3_h_s", { 1, 0, 0, 1, 0, 1 }},
  {"p3_h_s0", "mode_p3_h_s0", { 1, 0, 0, 1, 0, 0 }},
  {"p3_h0_s", "mode_p3_h0_s", { 0, 0, 0, 1, 0, 1 }},
  {"p3_h0_s0", "mode_p3_h0_s0", { 0, 0, 0, 1, 0, 0 }},
  {"q2_h_s", "mode_q2_h_s", { 1, 0, 0, 0, 1, 1 }},
  {"q2_h_s0", "mode_q2_h_s0", { 1, 0, 0, 0, 1, 0 }},
  {"q2_h0_s", "mode_q2_h0_s", { 0, 0, 0, 0, 1, 1 }},
  {"q2_h0_s0", "mode_q2_h0_s0", { 0, 0, 0, 0, 1, 0 }},
  {"q3_h_s", "mode_q3_h_s", { 1, 0, 0, 1, 1, 1 }},
  {"q3_h_s0", "mode_q3_h_s0", { 1, 0, 0, 1, 1, 0 }},
  {"q3_h0_s", "mode_q3_h0_s", { 0, 0, 0, 1, 1, 1 }},
  {"q3_h0_s0", "mode_q3_h0_s0", { 0, 0, 0, 1, 1, 0 }},
  {"n1_h_s", "mode_n1_h_s", { 1, 1, 1, 0, 0, 1 }},
  {"n1_h_s0", "mode_n1_h_s0", { 1, 1, 1, 0, 0, 0 }},
  {"n1_h0_s", "mode_n1_h0_s", { 0, 1, 1, 0, 0, 1 }},
  {"n1_h0_s0", "mode_n1_h0_s0", { 0, 1, 1, 0, 0, 0 }},
  {"p2_h_s", "mode_p2_h_s", { 1, 0, 0, 0, 0, 1 }},
  {"p2_h_s0", "mode_p2_h_s0", { 1, 0, 0, 0, 0, 0 }},
  {"p2_h0_s", "mode_p2_h0_s", { 0, 0, 0, 0, 0, 1 }},
  {"p2_h0_s0", "mode_p2_h0_s0", { 0, 0, 0, 0, 0, 0 }},
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
    case 0: return mode_q1_h_s(arg, res, iw, w, 0);
    case 1: return mode_q1_h_s0(arg, res, iw, w, 0);
    case 2: return mode_q1_h0_s(arg, res, iw, w, 0);
    case 3: return mode_q1_h0_s0(arg, res, iw, w, 0);
    case 4: return mode_n3_h_s(arg, res, iw, w, 0);
    case 5: return mode_n3_h_s0(arg, res, iw, w, 0);
    case 6: return mode_n3_h0_s(arg, res, iw, w, 0);
    case 7: return mode_n3_h0_s0(arg, res, iw, w, 0);
    case 8: return mode_p1_h_s(arg, res, iw, w, 0);
    case 9: return mode_p1_h_s0(arg, res, iw, w, 0);
    case 10: return mode_p1_h0_s(arg, res, iw, w, 0);
    case 11: return mode_p1_h0_s0(arg, res, iw, w, 0);
    case 12: return mode_n2_h_s(arg, res, iw, w, 0);
    case 13: return mode_n2_h_s0(arg, res, iw, w, 0);
    case 14: return mode_n2_h0_s(arg, res, iw, w, 0);
    case 15: return mode_n2_h0_s0(arg, res, iw, w, 0);
    case 16: return mode_p3_h_s(arg, res, iw, w, 0);
    case 17: return mode_p3_h_s0(arg, res, iw, w, 0);
    case 18: return mode_p3_h0_s(arg, res, iw, w, 0);
    case 19: return mode_p3_h0_s0(arg, res, iw, w, 0);
    case 20: return mode_q2_h_s(arg, res, iw, w, 0);
    case 21: return mode_q2_h_s0(arg, res, iw, w, 0);
    case 22: return mode_q2_h0_s(arg, res, iw, w, 0);
    case 23: return mode_q2_h0_s0(arg, res, iw, w, 0);
    case 24: return mode_q3_h_s(arg, res, iw, w, 0);
    case 25: return mode_q3_h_s0(arg, res, iw, w, 0);
    case 26: return mode_q3_h0_s(arg, res, iw, w, 0);
    case 27: return mode_q3_h0_s0(arg, res, iw, w, 0);
    case 28: return mode_n1_h_s(arg, res, iw, w, 0);
    case 29: return mode_n1_h_s0(arg, res, iw, w, 0);
    case 30: return mode_n1_h0_s(arg, res, iw, w, 0);
    case 31: return mode_n1_h0_s0(arg, res, iw, w, 0);
    case 32: return mode_p2_h_s(arg, res, iw, w, 0);
    case 33: return mode_p2_h_s0(arg, res, iw, w, 0);
    case 34: return mode_p2_h0_s(arg, res, iw, w, 0);
    case 35: return mode_p2_h0_s0(arg, res, iw, w, 0);
    default: return -1;
  }
}
