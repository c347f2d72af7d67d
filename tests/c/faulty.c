/*
 * faulty.c: a law of the C API that misbehaves on purpose, for tests/tests/c_api.rs. The
 * fault comes from the environment, AMB_FAULT (the plant passes its own to the controller):
 *   nan      update answers NaN from sample 100 on
 *   inf      update answers +inf on x and -inf on y from sample 100 on
 *   abort    update aborts at sample 100 (after a line on stderr)
 *   closefds update closes every file descriptor from 3 to 1023 at sample 100 (the library's
 *            own: its IPC's, its lock's) after a line on stderr, and answers on
 *   null     the law's update pointer is NULL
 *   refuse   build refuses the design with a message
 *   version  the law says it was built against ABI version 99
 *   (other)  a plain law: zero currents and the bias; it reads `gain` (> 0) from the parameters
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amb_testbed_controller.h"

typedef struct faulty {
    const char *fault;
    double bias_y;
} faulty;

static void *faulty_build(void *context, const amb_design *design, amb_params *params, char *error, size_t error_len) {
    const char *fault = context;
    double gain;
    if (amb_params_number(params, "gain", "", 1.0, AMB_CHECK_POSITIVE, 0.0, 0.0, &gain) != 0) {
        return NULL;
    }
    if (strcmp(fault, "refuse") == 0) {
        snprintf(error, error_len, "cannot drive a plane of k_e = %g N/m", design->plane[0].stiffness_n_per_m);
        return NULL;
    }
    faulty *law = calloc(1, sizeof *law);
    const amb_loop_constants *c = &design->plane[0].constants;
    law->fault = fault;
    law->bias_y = c->rotor_mass_kg * c->gravity_m_s2 / c->ki_n_per_a;
    return law;
}

static void faulty_update(void *state, const amb_sample *s, double *current_a) {
    faulty *law = state;
    if (s->seq >= 100 && strcmp(law->fault, "abort") == 0) {
        fprintf(stderr, "faulty: aborting at sample %llu\n", (unsigned long long)s->seq);
        fflush(stderr);
        abort();
    }
    if (s->seq == 100 && strcmp(law->fault, "closefds") == 0) {
        fprintf(stderr, "faulty: closing the file descriptors 3 to 1023 at sample 100\n");
        fflush(stderr);
        for (int fd = 3; fd < 1024; fd++) {
            close(fd);
        }
    }
    if (s->seq >= 100 && strcmp(law->fault, "inf") == 0) {
        current_a[0] = INFINITY;
        current_a[1] = -INFINITY;
        return;
    }
    double v = (s->seq >= 100 && strcmp(law->fault, "nan") == 0) ? NAN : 0.0;
    current_a[0] = v;
    current_a[1] = law->bias_y + v;
}

static void faulty_reset(void *state) {
    (void)state;
}

static void faulty_drop(void *state) {
    free(state);
}

int main(int argc, char **argv) {
    const char *fault = getenv("AMB_FAULT");
    if (fault == NULL) {
        fault = "";
    }
    amb_law law = {
        .abi_version = strcmp(fault, "version") == 0 ? 99u : AMB_CONTROLLER_ABI_VERSION,
        .name = "faulty",
        .context = (void *)fault,
        .build = faulty_build,
        .update = strcmp(fault, "null") == 0 ? NULL : faulty_update,
        .reset = faulty_reset,
        .drop = faulty_drop,
    };
    return amb_serve(&law, 1, argc, argv);
}
