/* apexseal_model.h: indices and mode numbers of the generated apex-seal model.
 * Rendered by apexseal from templates/apexseal_model.in.h; do not edit (run `apexseal generate`).
 * Effects: {{ effects_label }}. Input hash: {{ input_hash }}.
 * All Functions take (theta, x[APEXSEAL_NX], [a[APEXSEAL_NG]], p[APEXSEAL_NP], u[APEXSEAL_NU]).
 */
#ifndef APEXSEAL_MODEL_H
#define APEXSEAL_MODEL_H

#ifdef __cplusplus
extern "C" {
#endif

#define APEXSEAL_INPUT_HASH "{{ input_hash }}"

/* state x */
#define APEXSEAL_NX {{ state|length }}
{% for name in state %}
#define APEXSEAL_X_{{ name|upper }} {{ loop.index0 }}
{% endfor %}

/* parameters p (derive.symbols.PARAMETER_NAMES) */
#define APEXSEAL_NP {{ parameters|length }}
{% for name in parameters %}
#define APEXSEAL_P_{{ name|upper }} {{ loop.index0 }}
{% endfor %}

/* inputs u: chamber pressures */
#define APEXSEAL_NU {{ inputs|length }}
{% for name in inputs %}
#define APEXSEAL_U_{{ name|upper }} {{ loop.index0 }}
{% endfor %}

/* contact guards g (closed while g < 0) = order of the activations a */
#define APEXSEAL_NG {{ guards|length }}
{% for name in guards %}
#define APEXSEAL_G_{{ name|upper }} {{ loop.index0 }}
{% endfor %}

/* outputs y */
#define APEXSEAL_NY {{ outputs|length }}
{% for name in outputs %}
#define APEXSEAL_Y_{{ name|upper }} {{ loop.index0 }}
{% endfor %}

/* modes: the groove case of Algorithm 3, then each other contact closed or open by its declared label (e.g. h, h0) */
#define APEXSEAL_NMODES {{ modes|length }}
{% for m in modes %}
#define APEXSEAL_MODE_{{ m.label|upper }} {{ m.index }}
{% endfor %}

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
