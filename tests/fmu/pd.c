/* A PD controller as an FMU, for tests/tests/fmu_controller.rs (issue 29 item 1): the
 * registry's `pd` (controller/src/pd.rs) in C, with the same arithmetic, so that its trace is
 * the Rust law's byte for byte. Built by the test with the system C compiler, as
 *
 *   FMI 2.0 co-simulation  -DFMI=2            (fmi2DoStep: the backward difference over h)
 *   FMI 3.0 co-simulation  -DFMI=3            (fmi3DoStep: the same)
 *   FMI 2.0 model exchange -DFMI=2 -DME       (the derivative from a first-order state
 *                                              x' = (u - x) / tau, the host integrating x)
 *
 * each with -DAXES=2 (planar: sensor_x, sensor_y -> current_x, current_y) or -DAXES=4
 * (two-plane: sensor_x_a, sensor_y_a, sensor_x_b, sensor_y_b -> current_...), and the
 * modelDescription.xml the test writes with the value references below.
 *
 * Parameters: kp, kd, amp_gain, bias_y (plane A; the planar model's), kp_b, kd_b, amp_gain_b,
 * bias_y_b (plane B), tau (model exchange), and the misbehaviours the tests need: fault
 * (0 none, 1 Discard, 2 Error, 3 Fatal from the step, 4 NaN currents, 5 SIGSEGV, 6 hang)
 * from step fault_tick on.
 *
 * The FMI types are written here from the standard (FMI 2.0.4, FMI 3.0): only what is used. */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef AXES
#define AXES 2
#endif

#define EXPORT __attribute__((visibility("default")))

enum { VR_SENSOR = 1, VR_SPEED = 10, VR_ANGLE = 11, VR_TIME = 12, VR_CURRENT = 20,
       VR_KP = 30, VR_KD = 31, VR_AMP = 32, VR_BIAS = 33, VR_KP_B = 34, VR_KD_B = 35, VR_AMP_B = 36,
       VR_BIAS_B = 37, VR_TAU = 38, VR_FAULT = 40, VR_FAULT_TICK = 41 };

typedef struct {
    double u[AXES], prev[AXES], out[AXES], x[AXES];
    double speed, angle, time;
    double kp[2], kd[2], amp[2], bias[2], tau;
    int fault, fault_tick, ticks, first;
} Pd;

static double *real_of(Pd *c, unsigned vr) {
    if (vr >= VR_SENSOR && vr < VR_SENSOR + AXES) return &c->u[vr - VR_SENSOR];
    if (vr >= VR_CURRENT && vr < VR_CURRENT + AXES) return &c->out[vr - VR_CURRENT];
    switch (vr) {
    case VR_SPEED: return &c->speed;
    case VR_ANGLE: return &c->angle;
    case VR_TIME: return &c->time;
    case VR_KP: return &c->kp[0];
    case VR_KD: return &c->kd[0];
    case VR_AMP: return &c->amp[0];
    case VR_BIAS: return &c->bias[0];
    case VR_KP_B: return &c->kp[1];
    case VR_KD_B: return &c->kd[1];
    case VR_AMP_B: return &c->amp[1];
    case VR_BIAS_B: return &c->bias[1];
    case VR_TAU: return &c->tau;
    default: return NULL;
    }
}

static Pd *create(void) {
    Pd *c = calloc(1, sizeof(Pd));
    if (!c) return NULL;
    for (int p = 0; p < 2; p++) { c->kp[p] = 1.0; c->kd[p] = 0.0; c->amp[p] = 1.0; }
    c->tau = 1e-4;
    c->first = 1;
    return c;
}

/* i = bias - A_a (k_p u + k_d u_dot), per axis; bias on y only (as PdGains::current). */
static void law(Pd *c, const double *u_dot) {
    for (int k = 0; k < AXES; k++) {
        int p = k / 2;
        double bias = (k % 2 == 1) ? c->bias[p] : 0.0;
        c->out[k] = bias - c->amp[p] * (c->kp[p] * c->u[k] + c->kd[p] * u_dot[k]);
    }
}

/* 0 OK; otherwise the status the fault asks for (2 Discard, 3 Error, 4 Fatal). */
static int misbehave(Pd *c) {
    if (c->fault == 0 || c->ticks < c->fault_tick) return 0;
    switch (c->fault) {
    case 1: return 2;
    case 2: return 3;
    case 3: return 4;
    case 4: for (int k = 0; k < AXES; k++) c->out[k] = NAN; return 0;
    case 5: { volatile int *nowhere = NULL; *nowhere = 1; return 0; }
    case 6: for (;;) sleep(1);
    default: return 0;
    }
}

/* One co-simulation step over h: the backward difference (0 at the first step). */
__attribute__((unused)) static int step(Pd *c, double h) {
    double u_dot[AXES];
    for (int k = 0; k < AXES; k++) u_dot[k] = c->first ? 0.0 : (c->u[k] - c->prev[k]) / h;
    law(c, u_dot);
    for (int k = 0; k < AXES; k++) c->prev[k] = c->u[k];
    c->first = 0;
    int s = misbehave(c);
    c->ticks++;
    return s;
}

#if FMI == 2
typedef void *fmi2Component;
typedef void (*fmi2Logger)(void *, const char *, int, const char *, const char *, ...);
typedef struct {
    fmi2Logger logger;
    void *(*allocate)(size_t, size_t);
    void (*release)(void *);
    void *step_finished;
    void *env;
} fmi2CallbackFunctions;
typedef struct {
    int newDiscreteStatesNeeded, terminateSimulation, nominalsChanged, valuesChanged, nextEventTimeDefined;
    double nextEventTime;
} fmi2EventInfo;

static fmi2Logger logger;

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT fmi2Component fmi2Instantiate(const char *name, int type, const char *guid, const char *resources,
                                     const fmi2CallbackFunctions *f, int visible, int logging) {
    (void)type; (void)guid; (void)resources; (void)visible; (void)logging;
    logger = f->logger;
    Pd *c = create();
    if (c && logger) logger(f->env, name, 0, "logAll", "pd: instantiated");
    return c;
}
EXPORT void fmi2FreeInstance(fmi2Component c) { free(c); }
EXPORT int fmi2SetupExperiment(fmi2Component c, int a, double b, double d, int e, double g) {
    (void)c; (void)a; (void)b; (void)d; (void)e; (void)g; return 0; }
EXPORT int fmi2EnterInitializationMode(fmi2Component c) { (void)c; return 0; }
EXPORT int fmi2ExitInitializationMode(fmi2Component c) { (void)c; return 0; }
EXPORT int fmi2Terminate(fmi2Component c) { (void)c; return 0; }
EXPORT int fmi2Reset(fmi2Component c) { (void)c; return 0; }
EXPORT int fmi2SetDebugLogging(fmi2Component c, int on, size_t n, const char *const cats[]) {
    (void)c; (void)on; (void)n; (void)cats; return 0; }
EXPORT int fmi2SetReal(fmi2Component c, const unsigned *vr, size_t n, const double *v) {
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; *p = v[i]; }
    return 0;
}
#ifdef ME
/* The output at the current states and inputs: u_dot = (u - x) / tau; 0 at the first
 * sample, as pd's backward difference (x is then 0, not the previous sample). */
static void outputs(Pd *c) {
    double u_dot[AXES];
    for (int k = 0; k < AXES; k++) u_dot[k] = c->ticks == 0 ? 0.0 : (c->u[k] - c->x[k]) / c->tau;
    law(c, u_dot);
}
#endif
EXPORT int fmi2GetReal(fmi2Component c, const unsigned *vr, size_t n, double *v) {
#ifdef ME
    outputs(c);
#endif
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; v[i] = *p; }
    return 0;
}
EXPORT int fmi2SetInteger(fmi2Component c, const unsigned *vr, size_t n, const int *v) {
    Pd *pd = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) pd->fault = v[i];
        else if (vr[i] == VR_FAULT_TICK) pd->fault_tick = v[i];
        else return 3;
    }
    return 0;
}
EXPORT int fmi2GetInteger(fmi2Component c, const unsigned *vr, size_t n, int *v) {
    (void)c; (void)vr; for (size_t i = 0; i < n; i++) v[i] = 0; return 0; }
EXPORT int fmi2SetBoolean(fmi2Component c, const unsigned *vr, size_t n, const int *v) {
    (void)c; (void)vr; (void)n; (void)v; return 3; }
EXPORT int fmi2SetString(fmi2Component c, const unsigned *vr, size_t n, const char *const *v) {
    (void)c; (void)vr; (void)n; (void)v; return 3; }
#ifndef ME
EXPORT int fmi2DoStep(fmi2Component c, double t, double h, int no_prior) {
    (void)t; (void)no_prior;
    return step(c, h);
}
#else
EXPORT int fmi2SetTime(fmi2Component c, double t) { ((Pd *)c)->time = t; return 0; }
EXPORT int fmi2SetContinuousStates(fmi2Component c, const double *x, size_t n) {
    Pd *pd = c; if (n != AXES) return 3; memcpy(pd->x, x, sizeof pd->x); return 0; }
EXPORT int fmi2GetContinuousStates(fmi2Component c, double *x, size_t n) {
    Pd *pd = c; if (n != AXES) return 3; memcpy(x, pd->x, sizeof pd->x); return 0; }
EXPORT int fmi2GetDerivatives(fmi2Component c, double *dx, size_t n) {
    Pd *pd = c;
    if (n != AXES) return 3;
    for (int k = 0; k < AXES; k++) dx[k] = (pd->u[k] - pd->x[k]) / pd->tau;
    return 0;
}
EXPORT int fmi2GetEventIndicators(fmi2Component c, double *z, size_t n) { (void)c; (void)z; (void)n; return 0; }
EXPORT int fmi2CompletedIntegratorStep(fmi2Component c, int no_prior, int *enter, int *terminate) {
    Pd *pd = c; (void)no_prior;
    *enter = 0; *terminate = 0;
    int s = misbehave(pd);
    pd->ticks++;
    return s;
}
EXPORT int fmi2EnterEventMode(fmi2Component c) { (void)c; return 0; }
EXPORT int fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    (void)c; memset(info, 0, sizeof *info); return 0; }
EXPORT int fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return 0; }
#endif
#endif

#if FMI == 3
typedef void *fmi3Instance;
typedef void (*fmi3Log)(void *, int, const char *, const char *);

EXPORT const char *fmi3GetVersion(void) { return "3.0"; }
EXPORT fmi3Instance fmi3InstantiateCoSimulation(const char *name, const char *token, const char *resources,
        bool visible, bool logging, bool event_mode, bool early_return, const unsigned *required, size_t n_required,
        void *env, fmi3Log log, void *intermediate) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)event_mode;
    (void)early_return; (void)required; (void)n_required; (void)intermediate;
    Pd *c = create();
    if (c && log) log(env, 0, "logAll", "pd: instantiated (FMI 3.0)");
    return c;
}
EXPORT void fmi3FreeInstance(fmi3Instance c) { free(c); }
EXPORT int fmi3EnterInitializationMode(fmi3Instance c, bool a, double b, double d, bool e, double g) {
    (void)c; (void)a; (void)b; (void)d; (void)e; (void)g; return 0; }
EXPORT int fmi3ExitInitializationMode(fmi3Instance c) { (void)c; return 0; }
EXPORT int fmi3Terminate(fmi3Instance c) { (void)c; return 0; }
EXPORT int fmi3SetFloat64(fmi3Instance c, const unsigned *vr, size_t n, const double *v, size_t nv) {
    (void)nv;
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; *p = v[i]; }
    return 0;
}
EXPORT int fmi3GetFloat64(fmi3Instance c, const unsigned *vr, size_t n, double *v, size_t nv) {
    (void)nv;
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; v[i] = *p; }
    return 0;
}
EXPORT int fmi3SetInt32(fmi3Instance c, const unsigned *vr, size_t n, const int *v, size_t nv) {
    Pd *pd = c; (void)nv;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) pd->fault = v[i];
        else if (vr[i] == VR_FAULT_TICK) pd->fault_tick = v[i];
        else return 3;
    }
    return 0;
}
EXPORT int fmi3SetBoolean(fmi3Instance c, const unsigned *vr, size_t n, const bool *v, size_t nv) {
    (void)c; (void)vr; (void)n; (void)v; (void)nv; return 3; }
EXPORT int fmi3SetString(fmi3Instance c, const unsigned *vr, size_t n, const char *const *v, size_t nv) {
    (void)c; (void)vr; (void)n; (void)v; (void)nv; return 3; }
EXPORT int fmi3DoStep(fmi3Instance c, double t, double h, bool no_prior, bool *event, bool *terminate,
                      bool *early, double *last) {
    (void)no_prior;
    *event = false; *terminate = false; *early = false; *last = t + h;
    return step(c, h);
}
#endif
