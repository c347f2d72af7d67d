/*
 * pd.c: the testbed's `pd` law in C, served by libamb_testbed_controller.
 * Its lockstep trace is the Rust pd's, byte for byte (tests/tests/c_api.rs):
 * the same IEEE 754 operations in the same order as controller/src/pd.rs
 * (docs/wire-protocol.md, "The shipped laws, exactly"); compile with
 * -ffp-contract=off so that no multiply-add is fused.
 *
 *   cargo build --release
 *   cc -std=c11 -O2 -ffp-contract=off -Icontroller/include examples/c/pd.c \
 *      target/release/libamb_testbed_controller.a -lgcc_s -lutil -lrt -lpthread -lm -ldl -lc -o pd-c
 *   target/release/plant run config/cosim-10g.toml --set controller.law='"pd"' --set 'controller.command=["./pd-c"]'
 *
 * One PD per bearing plane (the planar model: one; the two-plane rotor: two,
 * each from its own plane's design), as the registry's pd. It takes one
 * parameter of its own, `gain` (default 1: the registry's pd), a factor on
 * k_p, to show the parameter reader:
 *   --set 'controller.params={gain = 1.2}'
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "amb_testbed_controller.h"

/* One bearing plane's PD. */
typedef struct plane_pd {
    double kp, kd, amp;
    double bias[2];
    double previous[2];
} plane_pd;

/* The law: one PD per plane (decentralised, as the registry's pd on a two-plane rotor). */
typedef struct pd {
    uint32_t planes;
    double period;
    int has_previous;
    plane_pd plane[AMB_MAX_PLANES];
} pd;

static void *pd_build(void *context, const amb_design *design, amb_params *params, char *error, size_t error_len) {
    (void)context;
    double gain;
    if (amb_params_number(params, "gain", "", 1.0, AMB_CHECK_POSITIVE, 0.0, 0.0, &gain) != 0) {
        return NULL; /* the reader's message names the law, the key, the value */
    }
    if (design->planes < 1 || design->planes > AMB_MAX_PLANES || design->axes != 2 * design->planes) {
        snprintf(error, error_len, "drives 2 axes per plane, not %u axes on %u planes", design->axes, design->planes);
        return NULL;
    }
    pd *law = calloc(1, sizeof *law);
    if (law == NULL) {
        snprintf(error, error_len, "out of memory");
        return NULL;
    }
    law->planes = design->planes;
    law->period = design->period_s;
    for (uint32_t p = 0; p < design->planes; p++) {
        const amb_plane_design *d = &design->plane[p];
        const amb_loop_constants *c = &d->constants;
        plane_pd *g = &law->plane[p];
        /* As PdGains::from_design, left to right. */
        double loop_gain = c->ki_n_per_a * c->amp_gain_a_per_v * c->sensor_gain_v_per_m;
        double c_e = 2.0 * d->damping_ratio * sqrt(d->stiffness_n_per_m * c->rotor_mass_kg);
        g->kp = gain * ((d->stiffness_n_per_m + c->ks_n_per_m) / loop_gain); /* 1.0 * x is x, bit for bit */
        g->kd = c_e / loop_gain;
        g->amp = c->amp_gain_a_per_v;
        g->bias[0] = 0.0;
        g->bias[1] = d->gravity_bias ? c->rotor_mass_kg * c->gravity_m_s2 / c->ki_n_per_a : 0.0;
    }
    return law;
}

static void pd_update(void *state, const amb_sample *s, double *current_a) {
    pd *law = state;
    for (uint32_t p = 0; p < law->planes; p++) {
        plane_pd *g = &law->plane[p];
        for (int j = 0; j < 2; j++) {
            double u = s->sensor_v[2 * p + j];
            double rate = law->has_previous ? (u - g->previous[j]) / law->period : 0.0; /* backward difference */
            current_a[2 * p + j] = g->bias[j] - g->amp * (g->kp * u + g->kd * rate);
            g->previous[j] = u;
        }
    }
    law->has_previous = 1;
}

static void pd_reset(void *state) {
    ((pd *)state)->has_previous = 0;
}

static void pd_drop(void *state) {
    free(state);
}

int main(int argc, char **argv) {
    static const amb_law laws[] = {{
        .abi_version = AMB_CONTROLLER_ABI_VERSION,
        .name = "pd",
        .summary = "the design's PD, naively sampled, in C",
        .build = pd_build,
        .update = pd_update,
        .reset = pd_reset,
        .drop = pd_drop,
    }};
    return amb_serve(laws, sizeof laws / sizeof laws[0], argc, argv);
}
