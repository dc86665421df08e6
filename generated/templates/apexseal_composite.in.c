/* apexseal_composite.c: a composite integrator of the hybrid model, compiled into the model library.
 * Rendered by apexseal from templates/apexseal_composite.in.c; do not edit (run `apexseal generate`).
 * Effects: {{ effects_label }}.
 *
 * The run method `composite` (runtime/solving/composite.py; measured in docs/bench/composite.md): Dormand and
 * Prince's RK5(4) with events where contacts switch (the tight phase), and from `ring` rad after the last contact
 * event, or earlier once `stiff_steps` RK45 steps were found near their stability boundary (DOPRI5's stiffness
 * test, h |lambda| above `stiff_hlam`), the exponential Rosenbrock method exprb32 (Hochbruck, Ostermann and
 * Schweitzer, SIAM J. Numer. Anal. 47 (2009)) at `loose` times the tolerances with the rate states' tolerance
 * `quiet` times looser still (the quiet phase); a quiet step across which a zero function changes sign is given
 * back to the tight phase.
 * It integrates the scaled state against the crank angle through the library's hybrid_ode and hybrid_zero
 * (runtime/solving/hybrid.py): z = [scaled state, activations, event counts], e_i = (1 - 2 s_i) g_i / l.
 */
#include <math.h>
#include <string.h>

#include "apexseal_model.h"
{% for header in casadi_headers %}
#include "{{ header }}"
{% endfor %}

#define NX APEXSEAL_NX
#define NG APEXSEAL_NG
#define NZ (NX + 2 * NG)
#define NW (NX + 1) /* the integrated w: the scaled state and the crank angle since the call's start */
#define NM (NW + 3) /* the largest augmented matrix of the phi functions */
#define NU_CALL (2 * APEXSEAL_NU)
#define WORK 4096

typedef struct {
  const casadi_real* p; /* [parameters, crank angle at the start] */
  const casadi_real* U; /* per output interval: the pressures at tau = 0 and their slopes */
  /* per output interval, the parameters' lines as offsets from p: [a (NP), b (NP)], p(tau) = p + a + b tau (a
   * scene's schedule); NULL: the parameters are p all along */
  const casadi_real* L;
  casadi_real pt[APEXSEAL_NP + 1]; /* the parameters at the last inputs() */
  const casadi_real* rate; /* 1 for the rate states */
  casadi_real s[NG];
  long long evals;
  double hlam; /* the last RK45 step's estimate of h |lambda| (dp45) */
  const casadi_real* arg[16];
  casadi_real* res[16];
  casadi_int iw[WORK];
  casadi_real w[WORK];
} Ctx;

/* the library's inputs (t, z, p, u) at w in mode s, output interval k: c->arg[0..3], pointing at t and z (and p
 * at the parameters there, on interval k's lines where they follow a schedule) */
static void inputs(Ctx* c, const double* w, int k, double* t, double* z) {
  *t = w[NX];
  memcpy(z, w, NX * sizeof(double));
  memcpy(z + NX, c->s, NG * sizeof(double));
  memset(z + NX + NG, 0, NG * sizeof(double));
  c->arg[0] = t; c->arg[1] = z; c->arg[2] = c->p; c->arg[3] = c->U + NU_CALL * k;
  if (c->L) {
    const double* l = c->L + 2 * APEXSEAL_NP * k;
    for (int i = 0; i < APEXSEAL_NP; i++) c->pt[i] = c->p[i] + l[i] + l[APEXSEAL_NP + i] * *t;
    c->pt[APEXSEAL_NP] = c->p[APEXSEAL_NP];
    c->arg[2] = c->pt;
  }
}

/* dw/dtheta in mode s, output interval k */
static int F(Ctx* c, const double* w, int k, double* out) {
  double z[NZ], ode[NZ], t;
  inputs(c, w, k, &t, z);
  c->res[0] = ode;
  if (hybrid_ode(c->arg, c->res, c->iw, c->w, 0)) return 1;
  memcpy(out, ode, NX * sizeof(double));
  out[NX] = 1.0;
  c->evals++;
  return 0;
}

/* the zero functions e in mode s, output interval k */
static int zeros(Ctx* c, const double* w, int k, double* e) {
  double z[NZ], t;
  inputs(c, w, k, &t, z);
  c->res[0] = e;
  return hybrid_zero(c->arg, c->res, c->iw, c->w, 0);
}

/* ---------------------------------------------------------------- matrix exponential and phi functions */

static void mm(int n, const double* A, const double* B, double* C) {
  for (int i = 0; i < n * n; i++) C[i] = 0.0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double a = A[i * n + j]; /* no test for zero: the powers are dense, and a branch per entry costs more */
      for (int q = 0; q < n; q++) C[i * n + q] += a * B[j * n + q];
    }
}

/* B := A^-1 B (n x n each) by Gaussian elimination with partial pivoting; A is overwritten */
static void solve(int n, double* A, double* B) {
  for (int c = 0; c < n; c++) {
    int piv = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(A[r * n + c]) > fabs(A[piv * n + c])) piv = r;
    if (piv != c)
      for (int j = 0; j < n; j++) {
        double t = A[c * n + j]; A[c * n + j] = A[piv * n + j]; A[piv * n + j] = t;
        t = B[c * n + j]; B[c * n + j] = B[piv * n + j]; B[piv * n + j] = t;
      }
    for (int r = c + 1; r < n; r++) {
      double f = A[r * n + c] / A[c * n + c];
      if (f != 0.0) {
        for (int j = c; j < n; j++) A[r * n + j] -= f * A[c * n + j];
        for (int j = 0; j < n; j++) B[r * n + j] -= f * B[c * n + j];
      }
    }
  }
  for (int c = n - 1; c >= 0; c--)
    for (int j = 0; j < n; j++) {
      double acc = B[c * n + j];
      for (int r = c + 1; r < n; r++) acc -= A[c * n + r] * B[r * n + j];
      B[c * n + j] = acc / A[c * n + c];
    }
}

/* D^-1 A D in place, D = diag(d) of powers of two that bring each row's and column's off-diagonal 1-norms
 * together (Parlett and Reinsch, Numer. Math. 13 (1969)): the same exponential up to the exact similarity, a far
 * smaller norm (the contacts' stiffness sits in a few entries of the Jacobian), so fewer squarings. */
static void balance(int n, double* A, double* d) {
  for (int i = 0; i < n; i++) d[i] = 1.0;
  for (int done = 0, sweep = 0; !done && sweep < 100; sweep++) { /* converges in a few sweeps */
    done = 1;
    for (int i = 0; i < n; i++) {
      double c = 0.0, r = 0.0;
      for (int j = 0; j < n; j++)
        if (j != i) { c += fabs(A[j * n + i]); r += fabs(A[i * n + j]); }
      if (c == 0.0 || r == 0.0 || !isfinite(c) || !isfinite(r)) continue; /* a non-finite step is rejected later */
      double total = c + r, f = 1.0;
      while (c < r / 2.0) { f *= 2.0; c *= 4.0; }
      while (c >= r * 2.0) { f /= 2.0; c /= 4.0; }
      if ((c + r) / f < 0.95 * total) {
        done = 0;
        d[i] *= f;
        for (int j = 0; j < n; j++) { A[i * n + j] /= f; A[j * n + i] *= f; }
      }
    }
  }
}

/* E = exp(A0) (n x n): balanced, then Pade (7, 7) with scaling and squaring (Higham, SIAM J. Matrix Anal. Appl.
 * 26 (2005)) */
static void expm(int n, const double* A0, double* E) {
  static const double b[8] = {17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0};
  double A[NM * NM], d[NM];
  double B[NM * NM], B2[NM * NM], B4[NM * NM], B6[NM * NM], odd[NM * NM], even[NM * NM], U[NM * NM], T[NM * NM];
  memcpy(A, A0, n * n * sizeof(double));
  balance(n, A, d);
  double norm = 0.0;
  for (int j = 0; j < n; j++) {
    double col = 0.0;
    for (int i = 0; i < n; i++) col += fabs(A[i * n + j]);
    if (col > norm) norm = col;
  }
  int sq = norm > 0.0 ? (int)ceil(log2(norm / 3.925724783138660)) : 0;
  if (sq < 0) sq = 0;
  double scale = ldexp(1.0, -sq);
  for (int i = 0; i < n * n; i++) B[i] = A[i] * scale;
  mm(n, B, B, B2);
  mm(n, B2, B2, B4);
  mm(n, B4, B2, B6);
  for (int i = 0; i < n * n; i++) {
    odd[i] = b[7] * B6[i] + b[5] * B4[i] + b[3] * B2[i];
    even[i] = b[6] * B6[i] + b[4] * B4[i] + b[2] * B2[i];
  }
  for (int i = 0; i < n; i++) { odd[i * n + i] += b[1]; even[i * n + i] += b[0]; }
  mm(n, B, odd, U);
  for (int i = 0; i < n * n; i++) { T[i] = even[i] - U[i]; E[i] = even[i] + U[i]; }
  solve(n, T, E);
  for (int r = 0; r < sq; r++) {
    mm(n, E, E, T);
    memcpy(E, T, n * n * sizeof(double));
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) E[i * n + j] *= d[i] / d[j];
}

/* out = phi_p(hJ) v: the exponential of [[hJ, v, 0], [0, 0, I], [0, 0, 0]] (size NW + p) */
static void phi(const double* hJ, const double* v, int p, double* out) {
  int n = NW + p;
  double M[NM * NM], E[NM * NM];
  memset(M, 0, sizeof(M));
  for (int i = 0; i < NW; i++) {
    for (int j = 0; j < NW; j++) M[i * n + j] = hJ[i * NW + j];
    M[i * n + NW] = v[i];
  }
  for (int i = 0; i < p - 1; i++) M[(NW + i) * n + NW + i + 1] = 1.0;
  expm(n, M, E);
  for (int i = 0; i < NW; i++) out[i] = E[i * n + NW + p - 1];
}

/* ---------------------------------------------------------------- the two steps */

/* the Jacobian of F at w (NW x NW; the crank angle's row is zero), column by column from the library's forward
 * derivative of hybrid_ode (fwd1_hybrid_ode: exact, at about the cost of the forward differences it replaced) */
static int jacobian(Ctx* c, const double* w, int k, const double* f0, double* J) {
  double z[NZ], t, out[NZ], dt, dz[NZ], dp[APEXSEAL_NP + 1], du[NU_CALL], col[NZ];
  inputs(c, w, k, &t, z);
  memset(out, 0, sizeof(out));
  memcpy(out, f0, NX * sizeof(double));
  memset(dp, 0, sizeof(dp));
  memset(du, 0, sizeof(du));
  c->arg[4] = out; c->arg[5] = &dt; c->arg[6] = dz; c->arg[7] = dp; c->arg[8] = du;
  c->res[0] = col;
  for (int j = 0; j < NW; j++) {
    memset(dz, 0, sizeof(dz));
    dt = 0.0;
    if (j < NX) dz[j] = 1.0; else dt = 1.0;
    if (c->L) /* along the crank angle the parameters move by their slopes */
      for (int i = 0; i < APEXSEAL_NP; i++) dp[i] = j < NX ? 0.0 : c->L[2 * APEXSEAL_NP * k + APEXSEAL_NP + i];
    if (fwd1_hybrid_ode(c->arg, c->res, c->iw, c->w, 0)) return 1;
    c->evals++;
    for (int i = 0; i < NX; i++) J[i * NW + j] = col[i];
    J[NX * NW + j] = 0.0;
  }
  return 0;
}

/* exprb32: U = w + h phi1(hJ) f0; w1 = U + 2h phi3(hJ) D, D = g(U) - g(w), g = F - J w; err = 2h phi3(hJ) D;
 * F(U) in output interval k1 (the step's end may lie in a later interval than its start) */
static int exprb(Ctx* c, const double* w, int k1, double h, const double* f0, const double* J, double* w1,
                 double* err) {
  double hJ[NW * NW], v[NW], U[NW], fU[NW], D[NW];
  for (int i = 0; i < NW * NW; i++) hJ[i] = h * J[i];
  phi(hJ, f0, 1, v);
  for (int i = 0; i < NW; i++) U[i] = w[i] + h * v[i];
  if (F(c, U, k1, fU)) return 1;
  for (int i = 0; i < NW; i++) {
    double JU = 0.0, Jw = 0.0;
    for (int j = 0; j < NW; j++) { JU += J[i * NW + j] * U[j]; Jw += J[i * NW + j] * w[j]; }
    D[i] = (fU[i] - JU) - (f0[i] - Jw);
  }
  phi(hJ, D, 3, v);
  for (int i = 0; i < NW; i++) { err[i] = 2.0 * h * v[i]; w1[i] = U[i] + err[i]; }
  return 0;
}

static const double DP_C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
static const double DP_A[7][6] = {
  {0, 0, 0, 0, 0, 0},
  {1.0 / 5, 0, 0, 0, 0, 0},
  {3.0 / 40, 9.0 / 40, 0, 0, 0, 0},
  {44.0 / 45, -56.0 / 15, 32.0 / 9, 0, 0, 0},
  {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0, 0},
  {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0},
  {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
static const double DP_E[7] = {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525,
                               -1.0 / 40};

/* RK5(4): w1 and the error estimate; K[6] = F(w1) (first same as last) */
static int dp45(Ctx* c, const double* w, int k, double h, const double* f0, double K[7][NW], double* w1,
                double* err) {
  double wj[NW], w6[NW];
  memcpy(K[0], f0, NW * sizeof(double));
  for (int j = 1; j < 7; j++) {
    for (int i = 0; i < NW; i++) {
      double acc = w[i];
      for (int m = 0; m < j; m++) acc += h * DP_A[j][m] * K[m][i];
      wj[i] = acc;
    }
    wj[NX] = w[NX] + DP_C[j] * h;
    if (j == 5) memcpy(w6, wj, sizeof(w6));
    if (F(c, wj, k, K[j])) return 1;
  }
  /* stiffness: the sixth and seventh stages are both at the step's end, so h |f(w7) - f(w6)| / |w7 - w6|
   * estimates h |lambda| of the dominant eigenvalue (Hairer and Wanner, Solving ODEs II, Sec. IV.2; DOPRI5) */
  double num = 0.0, den = 0.0;
  for (int i = 0; i < NX; i++) {
    double a = K[6][i] - K[5][i], b = wj[i] - w6[i];
    num += a * a;
    den += b * b;
  }
  c->hlam = den > 0.0 ? h * sqrt(num / den) : 0.0;
  for (int i = 0; i < NW; i++) {
    double e = 0.0;
    for (int m = 0; m < 7; m++) e += h * DP_E[m] * K[m][i];
    err[i] = e;
  }
  memcpy(w1, wj, NW * sizeof(double)); /* the seventh stage's point is the fifth-order solution */
  w1[NX] = w[NX] + h;
  return 0;
}

/* the error's largest ratio to its tolerance (atol + rtol |w|, the rate states' times `quiet`); NaN rejects */
static double norm(const Ctx* c, const double* w, const double* w1, const double* err, double rtol, double atol,
                   double quiet) {
  double out = 0.0;
  for (int i = 0; i < NX; i++) {
    double tol = (atol + rtol * fmax(fabs(w[i]), fabs(w1[i]))) * (c->rate[i] != 0.0 ? quiet : 1.0);
    double r = fabs(err[i]) / tol;
    if (isnan(r)) return r; /* the step is rejected */
    if (r > out) out = r;
  }
  return out;
}

/* ---------------------------------------------------------------- event location */

/* 1 when a zero function crossed from + to - over a step (e0 at its start, e1 at its end): a contact switches */
static int crossed(const double* e0, const double* e1) {
  int out = 0;
  for (int i = 0; i < NG; i++) out |= e0[i] >= 0.0 && e1[i] < 0.0;
  return out;
}

/* the continuous extension of RK5(4) (Shampine, Math. Comp. 46 (1986); order 4): w(theta h) = w + h sum_i
 * b_i(theta) K_i with b_i(theta) = theta (P_i0 + P_i1 theta + P_i2 theta^2 + P_i3 theta^3); b_i(1) are the
 * fifth-order weights */
static const double DP_P[7][4] = {
  {1.0, -8048581381.0 / 2820520608, 8663915743.0 / 2820520608, -12715105075.0 / 11282082432},
  {0, 0, 0, 0},
  {0, 131558114200.0 / 32700410799, -68118460800.0 / 10900136933, 87487479700.0 / 32700410799},
  {0, -1754552775.0 / 470086768, 14199869525.0 / 1410260304, -10690763975.0 / 1880347072},
  {0, 127303824393.0 / 49829197408, -318862633887.0 / 49829197408, 701980252875.0 / 199316789632},
  {0, -282668133.0 / 205662961, 2019193451.0 / 616988883, -1453857185.0 / 822651844},
  {0, 40617522.0 / 29380423, -110615467.0 / 29380423, 69997945.0 / 29380423}};

/* the state at theta h inside the RK45 step of length h from w whose stages are K */
static void dense(const double* w, double h, const double K[7][NW], double theta, double* out) {
  double b[7];
  for (int i = 0; i < 7; i++)
    b[i] = theta * (DP_P[i][0] + theta * (DP_P[i][1] + theta * (DP_P[i][2] + theta * DP_P[i][3])));
  for (int j = 0; j < NW; j++) {
    double acc = 0.0;
    for (int i = 0; i < 7; i++) acc += b[i] * K[i][j];
    out[j] = w[j] + h * acc;
  }
  out[NX] = w[NX] + theta * h;
}

/* the far side b (in (0, hh], to ev_tol) of the earliest crossing of the zero functions that crossed on the RK45
 * step of length hh from w (e0 >= 0 > e1 at its end), by the Illinois method on the step's length: the states
 * inside the step from its continuous extension (its stages K, read only) or, on_steps, from RK45 steps of that
 * length (K is overwritten) */
static int illinois(Ctx* c, const double* w, int k, double hh, const double* f0, double K[7][NW], const double* e0,
                    const double* e1, double ev_tol, int on_steps, double* b_out) {
  double a = 0.0, b = hh, fa = INFINITY, fb = INFINITY, em[NG], wm[NW], err[NW];
  for (int i = 0; i < NG; i++)
    if (e0[i] >= 0.0 && e1[i] < 0.0) { fa = fmin(fa, e0[i]); fb = fmin(fb, e1[i]); }
  int side = 0;
  for (int it = 1; b - a > ev_tol && it <= 100; it++) {
    double m = b - fb * (b - a) / (fb - fa);
    if (!(a < m && m < b) || it % 4 == 0) m = 0.5 * (a + b);
    if (on_steps ? dp45(c, w, k, m, f0, K, wm, err) : (dense(w, hh, (const double (*)[NW])K, m / hh, wm), 0))
      return 1;
    if (zeros(c, wm, k, em)) return 1;
    double fm = INFINITY;
    for (int i = 0; i < NG; i++)
      if (e0[i] >= 0.0) fm = fmin(fm, em[i]);
    if (fm < 0.0) { b = m; fb = fm; if (side == -1) fa *= 0.5; side = -1; }
    else { a = m; fa = fm; if (side == 1) fb *= 0.5; side = 1; }
  }
  *b_out = b;
  return 0;
}

/* the earliest crossing on the RK45 step of length hh from w (stages K; e1 at its end), located on the step's
 * continuous extension (a zero function costs a fifth of an evaluation); one RK45 step from w to the located far
 * side gives w1 and e1 there. Where that step does not cross (the extension's error moved the zero), the crossing is
 * located with RK45 steps instead. K is overwritten. */
static int locate(Ctx* c, const double* w, int k, double hh, const double* f0, double K[7][NW], const double* e0,
                  double* e1, double ev_tol, double* w1) {
  double b, err[NW], e_end[NG];
  memcpy(e_end, e1, sizeof(e_end));
  for (int on_steps = 0; on_steps < 2; on_steps++) {
    if (illinois(c, w, k, hh, f0, K, e0, e_end, ev_tol, on_steps, &b)) return 1;
    if (dp45(c, w, k, b, f0, K, w1, err) || zeros(c, w1, k, e1)) return 1;
    if (crossed(e0, e1)) return 0;
  }
  return 0; /* RK45 steps located it: w1 is past the crossing as far as the steps tell */
}

/* ---------------------------------------------------------------- the run */

/* the output interval (of N, dth each) in which crank angle t ends a step: one that ends on an interval's end
 * belongs to that interval */
static int interval_at(double t, double dth, int N) {
  int j = (int)floor(t / dth - 1e-9);
  return j < 0 ? 0 : (j > N - 1 ? N - 1 : j);
}

/* 1 when the lines x = a + b t of intervals j and k (n of them, rows [a, b], one interval's every `stride`)
 * agree at crank angle t, to round-off */
static int lines_agree(const double* rows, int stride, int n, int j, int k, double t) {
  const double *a = rows + stride * j, *b = rows + stride * k;
  for (int i = 0; i < n; i++) {
    double ua = a[i] + a[n + i] * t, ub = b[i] + b[n + i] * t;
    if (fabs(ua - ub) > 1e-12 * fmax(1.0, fmax(fabs(ua), fabs(ub)))) return 0;
  }
  return 1;
}

/* 1 when the controls of intervals j and k (u = a + b t, rows [a, b]) and the parameters' lines agree at crank
 * angle t, to round-off */
static int agree_at(const Ctx* c, int j, int k, double t) {
  return lines_agree(c->U, NU_CALL, APEXSEAL_NU, j, k, t)
         && (!c->L || lines_agree(c->L, 2 * APEXSEAL_NP, APEXSEAL_NP, j, k, t));
}

/* 1 when the controls of interval k hold over interval j too (one line across both: the same values at j's ends) */
static int same_controls(const Ctx* c, int k, int j, double dth) {
  return agree_at(c, j, k, j * dth) && agree_at(c, j, k, (j + 1) * dth);
}

/* 1 when the controls jump at crank angle t, the end of interval k (the "steps" profile's interval means) */
static int jumps(const Ctx* c, int k, double t) {
  return !agree_at(c, k, k + 1, t);
}

/* the scaled state at crank angle t inside a step from (t0, w, f0) to (t1, w1, f1): cubic Hermite */
static void hermite(double t, double t0, const double* w, const double* f0, double t1, const double* w1,
                    const double* f1, double* out) {
  double h = t1 - t0, s = (t - t0) / h, s2 = s * s, s3 = s2 * s;
  double a = 2 * s3 - 3 * s2 + 1, b = s3 - 2 * s2 + s, c = -2 * s3 + 3 * s2, d = s3 - s2;
  for (int i = 0; i < NX; i++) out[i] = a * w[i] + b * h * f0[i] + c * w1[i] + d * h * f1[i];
}

/* the step after an accepted one of length hh, where h was proposed and fac is the error's factor: a step cut
 * short by an interval's end does not shrink the next one unless its error asks for it */
static double next_step(double h, double hh, double fac) {
  return hh < h && fac >= 1.0 ? fmax(h, hh * fac) : hh * fac;
}

/* Z row k: the scaled state x, the activations and the event counts */
static void emit(double* Z, int k, const double* x, const double* s, const double* counts) {
  memcpy(Z + (long long)k * NZ, x, NX * sizeof(double));
  memcpy(Z + (long long)k * NZ + NX, s, NG * sizeof(double));
  memcpy(Z + (long long)k * NZ + NX + NG, counts, NG * sizeof(double));
}

/* the steps counted so far, and when the current output interval began */
typedef struct {
  long long tight, quiet, rejected; /* accepted RK45 steps, accepted exprb32 steps, rejected steps of either */
  long long quiet_before, accepted_before, attempts_before; /* at the interval's start: quiet, accepted, all */
} Tally;

/* output interval k ends with the scaled state x: its row of Z, the fraction of its steps that were quiet, and a
 * new interval's tally */
static void close_interval(double* Z, double* phase, int k, const double* x, const double* s, const double* counts,
                           Tally* n) {
  long long n_k = n->tight + n->quiet - n->accepted_before;
  phase[k] = n_k ? (double)(n->quiet - n->quiet_before) / (double)n_k : 1.0;
  emit(Z, k, x, s, counts);
  n->quiet_before = n->quiet;
  n->accepted_before = n->tight + n->quiet;
  n->attempts_before = n->accepted_before + n->rejected;
}

/* Integrates the N output intervals of dth rad from z0 (NZ); writes the hybrid state at each interval's end into
 * Z (N x NZ, row-major) and, per interval, the fraction of its steps that were quiet into phase (N). A quiet step
 * may cross the ends of intervals whose controls are one line (the rows of a pressure table are coarser than the
 * output grid), and the states there are interpolated (cubic Hermite); every other step ends on the next end, and
 * where the controls jump there (interval means) the next interval's first step evaluates its own. *since is the
 * crank angle since the last contact event at the start (a call that goes on from another's end carries it; 0
 * starts in the tight phase), and on return at the end of the intervals done. The quiet phase starts `ring` rad
 * after the last event, or after `stiff_steps` RK45 steps near their stability boundary (their estimate of
 * h |lambda| above `stiff_hlam`) counted within this call (0: only after `ring`). stats (8): tight steps, quiet
 * steps, rejected steps, evaluations, Jacobians, events, quiet steps given back, intervals done. Returns 0; 1
 * when the model failed to evaluate, 2 when an output interval took more than max_steps steps (rejected ones
 * included), 3 when the model's work arrays exceed this file's, 4 after more than max_events events. L: per interval
 * the parameters' lines as offsets from p, [a (NP), b (NP)] (a scene's schedule), or NULL. */
int apexseal_composite_run(const double* z0, const double* p, const double* U, const double* L, const double* rate,
                           int N,
                           double dth, double rtol, double atol, double loose, double quiet, double ring,
                           long long stiff_steps, double stiff_hlam, double ev_tol, long long max_steps,
                           long long max_events, double* since, double* Z, double* phase, long long* stats) {
  Ctx ctx;
  Ctx* c = &ctx;
  casadi_int sz_arg, sz_res, sz_iw, sz_w, a2, r2, i2, w2, a3, r3, i3, w3;
  hybrid_ode_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  hybrid_zero_work(&a2, &r2, &i2, &w2);
  fwd1_hybrid_ode_work(&a3, &r3, &i3, &w3);
  if (sz_arg > 16 || a2 > 16 || a3 > 16 || sz_res > 16 || r2 > 16 || r3 > 16 || sz_iw > WORK || i2 > WORK ||
      i3 > WORK || sz_w > WORK || w2 > WORK || w3 > WORK)
    return 3;
  c->p = p; c->U = U; c->L = L; c->rate = rate; c->evals = 0;
  double w[NW], w1[NW], f0[NW], f1[NW], J[NW * NW], K[7][NW], err[NW], e0[NG], e1[NG], counts[NG], x[NX];
  memcpy(w, z0, NX * sizeof(double));
  w[NX] = 0.0;
  memcpy(c->s, z0 + NX, NG * sizeof(double));
  memcpy(counts, z0 + NX + NG, NG * sizeof(double));
  double h_t = 1e-5, h_q = 1e-3, last_event = -*since;
  long long jacobians = 0, events = 0, given_back = 0;
  Tally n = {0, 0, 0, 0, 0, 0};
  int stiff = 0, nonstiff = 0; /* RK45 steps found at its stability boundary, and since the last one */
  int status = 0, k = 0, known = 0; /* known: e0 holds the zero functions at w (those at the last step's end) */
  if (F(c, w, 0, f0)) { status = 1; goto done; }
  while (k < N) {
    double t_end = (k + 1) * dth, hh, e;
    if (w[NX] >= t_end * (1 - 1e-14)) { /* interval k is done */
      close_interval(Z, phase, k, w, c->s, counts, &n);
      k++;
      if (k < N && jumps(c, k - 1, w[NX])) { /* its controls: its own slopes and zero functions */
        if (F(c, w, k, f0)) { status = 1; goto done; }
        known = 0;
      }
      continue;
    }
    if (n.tight + n.quiet + n.rejected - n.attempts_before > max_steps) { status = 2; goto done; }
    if (events > max_events) { status = 4; goto done; }
    if (!known && zeros(c, w, k, e0)) { status = 1; goto done; }
    known = 1;
    if (w[NX] - last_event > ring || (stiff_steps > 0 && stiff >= stiff_steps)) { /* quiet: exprb32 */
      int k1 = k, last = k;
      while (last + 1 < N && same_controls(c, k, last + 1, dth)) last++; /* the step may reach the end of interval last */
      if (jacobian(c, w, k, f0, J)) { status = 1; goto done; }
      jacobians++;
      for (;;) {
        hh = fmin(h_q, (last + 1) * dth - w[NX]);
        k1 = interval_at(w[NX] + hh, dth, N);
        if (exprb(c, w, k1, hh, f0, J, w1, err)) { status = 1; goto done; }
        e = norm(c, w, w1, err, rtol * loose, atol * loose, quiet);
        if (e <= 1.0) break;
        n.rejected++;
        h_q = hh * (isfinite(e) ? fmax(0.2, 0.9 * pow(e, -1.0 / 3)) : 0.2);
      }
      if (zeros(c, w1, k1, e1)) { status = 1; goto done; }
      if (crossed(e0, e1)) { /* a switch ahead: the tight phase takes this step over */
        given_back++;
        last_event = w[NX];
        stiff = nonstiff = 0;
        h_t = fmin(h_t, hh);
        continue;
      }
      h_q = next_step(h_q, hh, fmin(5.0, fmax(0.2, 0.9 * pow(fmax(e, 1e-10), -1.0 / 3))));
      if (F(c, w1, k1, f1)) { status = 1; goto done; }
      n.quiet++;
      /* the intervals' ends the step crossed: their states interpolated, their phase quiet */
      for (double t_j = (k + 1) * dth; k < N && t_j < w1[NX] * (1 - 1e-14); t_j = (k + 1) * dth) {
        hermite(t_j, w[NX], w, f0, w1[NX], w1, f1, x);
        close_interval(Z, phase, k, x, c->s, counts, &n);
        k++;
      }
      memcpy(w, w1, sizeof(w));
      memcpy(f0, f1, sizeof(f0));
      memcpy(e0, e1, sizeof(e0));
      continue;
    }
    int retried = 0;
    for (;;) { /* tight: RK45 at rtol */
      hh = fmin(h_t, t_end - w[NX]);
      if (dp45(c, w, k, hh, f0, K, w1, err)) { status = 1; goto done; }
      e = norm(c, w, w1, err, rtol, atol, 1.0);
      if (e <= 1.0) break;
      n.rejected++;
      retried = 1;
      h_t = hh * (isfinite(e) ? fmax(0.2, 0.9 * pow(e, -1.0 / 5)) : 0.2);
    }
    if (zeros(c, w1, k, e1)) { status = 1; goto done; }
    if (crossed(e0, e1)) {
      if (locate(c, w, k, hh, f0, K, e0, e1, ev_tol, w1)) { status = 1; goto done; }
      for (int i = 0; i < NG; i++)
        if (e1[i] < 0.0) { /* toggled: the located contact and any that crossed with it */
          c->s[i] = 1.0 - c->s[i];
          counts[i] += 1.0;
          events++;
        }
      last_event = w1[NX];
      stiff = nonstiff = 0;
      h_t = fmax(0.5 * hh, 1e-9);
      memcpy(w, w1, sizeof(w));
      if (F(c, w, k, f0)) { status = 1; goto done; }
      known = 0; /* the toggled contacts' zero functions change sign */
    } else {
      h_t = next_step(h_t, hh, fmin(retried ? 1.0 : 5.0, fmax(0.2, 0.9 * pow(fmax(e, 1e-10), -1.0 / 5))));
      memcpy(w, w1, sizeof(w));
      memcpy(f0, K[6], sizeof(f0)); /* first same as last */
      if (c->hlam > stiff_hlam) { /* DOPRI5's count: a step near the boundary; six steps inside it forget them */
        stiff++;
        nonstiff = 0;
      } else if (++nonstiff >= 6) {
        stiff = 0;
      }
      memcpy(e0, e1, sizeof(e0));
    }
    n.tight++;
  }
done:
  *since = w[NX] - last_event;
  stats[0] = n.tight; stats[1] = n.quiet; stats[2] = n.rejected; stats[3] = c->evals;
  stats[4] = jacobians; stats[5] = events; stats[6] = given_back; stats[7] = k;
  return status;
}
