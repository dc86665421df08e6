/* apexseal_model.h: indices and mode numbers of the generated apex-seal model.
 * Rendered by apexseal from templates/apexseal_model.in.h; do not edit (run `apexseal generate`).
 * Effects: all. Input hash: 3960e40cfbb69485b333d2445ebfdf75fc772cfd329cee27558b898403140a71.
 * All Functions take (theta, x[APEXSEAL_NX], [a[APEXSEAL_NG]], p[APEXSEAL_NP], u[APEXSEAL_NU]).
 */
#ifndef APEXSEAL_MODEL_H
#define APEXSEAL_MODEL_H

#ifdef __cplusplus
extern "C" {
#endif

#define APEXSEAL_INPUT_HASH "3960e40cfbb69485b333d2445ebfdf75fc772cfd329cee27558b898403140a71"

/* state x */
#define APEXSEAL_NX 6
#define APEXSEAL_X_X 0
#define APEXSEAL_X_Y 1
#define APEXSEAL_X_PHI 2
#define APEXSEAL_X_XD 3
#define APEXSEAL_X_YD 4
#define APEXSEAL_X_PHID 5

/* parameters p (derive.symbols.PARAMETER_NAMES) */
#define APEXSEAL_NP 29
#define APEXSEAL_P_OMEGA 0
#define APEXSEAL_P_R 1
#define APEXSEAL_P_L 2
#define APEXSEAL_P_LI 3
#define APEXSEAL_P_DELTA_W 4
#define APEXSEAL_P_WS 5
#define APEXSEAL_P_WG 6
#define APEXSEAL_P_DS1 7
#define APEXSEAL_P_DS2 8
#define APEXSEAL_P_RO 9
#define APEXSEAL_P_BETA_O 10
#define APEXSEAL_P_BS 11
#define APEXSEAL_P_MS 12
#define APEXSEAL_P_ICG 13
#define APEXSEAL_P_ZETA0 14
#define APEXSEAL_P_V_EPS 15
#define APEXSEAL_P_KW 16
#define APEXSEAL_P_CW 17
#define APEXSEAL_P_MU1 18
#define APEXSEAL_P_KG1 19
#define APEXSEAL_P_KG2 20
#define APEXSEAL_P_KG3 21
#define APEXSEAL_P_KG4 22
#define APEXSEAL_P_CR 23
#define APEXSEAL_P_MU2 24
#define APEXSEAL_P_KS 25
#define APEXSEAL_P_DELTA_S 26
#define APEXSEAL_P_CS 27
#define APEXSEAL_P_MUS 28

/* inputs u: chamber pressures */
#define APEXSEAL_NU 2
#define APEXSEAL_U_PA 0
#define APEXSEAL_U_PB 1

/* contact guards g (closed while g < 0) = order of the activations a */
#define APEXSEAL_NG 6
#define APEXSEAL_G_XS5 0
#define APEXSEAL_G_B1 1
#define APEXSEAL_G_B2 2
#define APEXSEAL_G_B3 3
#define APEXSEAL_G_B4 4
#define APEXSEAL_G_SPRING 5

/* outputs y */
#define APEXSEAL_NY 39
#define APEXSEAL_Y_F_HOUSING_X 0
#define APEXSEAL_Y_F_HOUSING_Y 1
#define APEXSEAL_Y_M_HOUSING 2
#define APEXSEAL_Y_PF_HOUSING 3
#define APEXSEAL_Y_V_HOUSING 4
#define APEXSEAL_Y_F_I1_X 5
#define APEXSEAL_Y_F_I1_Y 6
#define APEXSEAL_Y_M_I1 7
#define APEXSEAL_Y_PF_I1 8
#define APEXSEAL_Y_V_I1 9
#define APEXSEAL_Y_F_C2_X 10
#define APEXSEAL_Y_F_C2_Y 11
#define APEXSEAL_Y_M_C2 12
#define APEXSEAL_Y_PF_C2 13
#define APEXSEAL_Y_V_C2 14
#define APEXSEAL_Y_F_I2_X 15
#define APEXSEAL_Y_F_I2_Y 16
#define APEXSEAL_Y_M_I2 17
#define APEXSEAL_Y_PF_I2 18
#define APEXSEAL_Y_V_I2 19
#define APEXSEAL_Y_F_C4_X 20
#define APEXSEAL_Y_F_C4_Y 21
#define APEXSEAL_Y_M_C4 22
#define APEXSEAL_Y_PF_C4 23
#define APEXSEAL_Y_V_C4 24
#define APEXSEAL_Y_F_SPRING_X 25
#define APEXSEAL_Y_F_SPRING_Y 26
#define APEXSEAL_Y_M_SPRING 27
#define APEXSEAL_Y_PF_SPRING 28
#define APEXSEAL_Y_V_SPRING 29
#define APEXSEAL_Y_F_PRESSURE_X 30
#define APEXSEAL_Y_F_PRESSURE_Y 31
#define APEXSEAL_Y_M_PRESSURE 32
#define APEXSEAL_Y_PF_TOTAL 33
#define APEXSEAL_Y_L1 34
#define APEXSEAL_Y_L2 35
#define APEXSEAL_Y_L3 36
#define APEXSEAL_Y_L4 37
#define APEXSEAL_Y_B_GAP 38

/* modes: the groove case of Algorithm 3, then each other contact closed or open by its declared label (e.g. h, h0) */
#define APEXSEAL_NMODES 36
#define APEXSEAL_MODE_Q1_H_S 0
#define APEXSEAL_MODE_Q1_H_S0 1
#define APEXSEAL_MODE_Q1_H0_S 2
#define APEXSEAL_MODE_Q1_H0_S0 3
#define APEXSEAL_MODE_N3_H_S 4
#define APEXSEAL_MODE_N3_H_S0 5
#define APEXSEAL_MODE_N3_H0_S 6
#define APEXSEAL_MODE_N3_H0_S0 7
#define APEXSEAL_MODE_P1_H_S 8
#define APEXSEAL_MODE_P1_H_S0 9
#define APEXSEAL_MODE_P1_H0_S 10
#define APEXSEAL_MODE_P1_H0_S0 11
#define APEXSEAL_MODE_N2_H_S 12
#define APEXSEAL_MODE_N2_H_S0 13
#define APEXSEAL_MODE_N2_H0_S 14
#define APEXSEAL_MODE_N2_H0_S0 15
#define APEXSEAL_MODE_P3_H_S 16
#define APEXSEAL_MODE_P3_H_S0 17
#define APEXSEAL_MODE_P3_H0_S 18
#define APEXSEAL_MODE_P3_H0_S0 19
#define APEXSEAL_MODE_Q2_H_S 20
#define APEXSEAL_MODE_Q2_H_S0 21
#define APEXSEAL_MODE_Q2_H0_S 22
#define APEXSEAL_MODE_Q2_H0_S0 23
#define APEXSEAL_MODE_Q3_H_S 24
#define APEXSEAL_MODE_Q3_H_S0 25
#define APEXSEAL_MODE_Q3_H0_S 26
#define APEXSEAL_MODE_Q3_H0_S0 27
#define APEXSEAL_MODE_N1_H_S 28
#define APEXSEAL_MODE_N1_H_S0 29
#define APEXSEAL_MODE_N1_H0_S 30
#define APEXSEAL_MODE_N1_H0_S0 31
#define APEXSEAL_MODE_P2_H_S 32
#define APEXSEAL_MODE_P2_H_S0 33
#define APEXSEAL_MODE_P2_H0_S 34
#define APEXSEAL_MODE_P2_H0_S0 35

/* The record this library was generated from: the loader compares it with the manifest it trusts. */
const char* apexseal_model_input_hash(void);

/* The named outputs and the guards at n samples in one call (apexseal_model.c); p_stride 0: the parameters
 * shared by every sample, APEXSEAL_NP: one vector per sample. */
int apexseal_outputs_block(const double* theta, const double* x, const double* a, const double* p, int p_stride,
                           const double* u, int n, double* y, double* g);

#ifdef __cplusplus
}
#endif

#endif /* APEXSEAL_MODEL_H */
