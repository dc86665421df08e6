/* apexseal_model.c: the generation record compiled into the model library.
 * Rendered by apexseal from templates/apexseal_model.in.c; do not edit (run `apexseal generate`).
 * Effects: {{ effects_label }}.
 */
#include "apexseal_model.h"

/* The manifest's input hash: the loader refuses a library whose hash is not the one of the manifest it trusts. */
const char* apexseal_model_input_hash(void) { return APEXSEAL_INPUT_HASH; }
