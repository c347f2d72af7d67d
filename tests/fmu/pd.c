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
 * (0 none, 1 Discard, 2 Error, 3 Fatal from the step, 4 NaN currents, 5 SIGSEGV, 6 hang,
 * 7 one per process, 8 _exit(0)) from step fault_tick on. "One per process" is an FMU that
 * takes what is the process's, as a pythonfmu FMU takes the Python interpreter: from its
 * step it holds an abstract socket named after the process, and aborts (as two Python hosts
 * in one process crash) when another instance of it, in any copy of the library, holds it.
 *
 * The FMI types: with -DFMI_HEADERS the headers FMPy ships (fmpy/c-code/fmi2Functions.h,
 * fmi3Functions.h; the include path given with -I), so that the compiler checks every
 * function here against the standard's declarations; without, the few declarations below,
 * written from the standard (FMI 2.0.4, FMI 3.0) under the same names: only what is used. */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <sys/socket.h>
#include <sys/un.h>
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
    int held; /* fault 7: the process's socket, or -1 */
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
    c->held = -1;
    return c;
}

/* Fault 7: binds the process's abstract socket; abort() when another instance holds it. */
static void hold_the_process(Pd *c) {
    struct sockaddr_un a;
    memset(&a, 0, sizeof a);
    a.sun_family = AF_UNIX;
    int n = snprintf(a.sun_path + 1, sizeof a.sun_path - 1, "amb-testbed-pd-fmu-%d", (int)getpid());
    c->held = socket(AF_UNIX, SOCK_STREAM, 0);
    if (c->held < 0 || bind(c->held, (struct sockaddr *)&a, (socklen_t)(offsetof(struct sockaddr_un, sun_path) + 1 + n)))
        abort();
}

static void destroy(Pd *c) {
    if (c && c->held >= 0) close(c->held);
    free(c);
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
    case 7: if (c->held < 0) hold_the_process(c); return 0;
    case 8: _exit(0);
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
#ifdef FMI_HEADERS
#include "fmi2Functions.h"
#else
typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef const char *fmi2String;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status;
typedef int fmi2Type;
typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...);
typedef struct {
    fmi2CallbackLogger logger;
    void *(*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void *);
    void *stepFinished;
    fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;
typedef struct {
    fmi2Boolean newDiscreteStatesNeeded, terminateSimulation, nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged, nextEventTimeDefined;
    fmi2Real nextEventTime;
} fmi2EventInfo;
#endif

static fmi2CallbackLogger logger;

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }
EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                                     const fmi2CallbackFunctions *f, fmi2Boolean visible, fmi2Boolean logging) {
    (void)type; (void)guid; (void)resources; (void)visible; (void)logging;
    logger = f->logger;
    Pd *c = create();
    if (c && logger) logger(f->componentEnvironment, name, 0, "logAll", "pd: instantiated");
    return c;
}
EXPORT void fmi2FreeInstance(fmi2Component c) { destroy(c); }
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean a, fmi2Real b, fmi2Real d, fmi2Boolean e,
                                      fmi2Real g) {
    (void)c; (void)a; (void)b; (void)d; (void)e; (void)g; return 0; }
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return 0; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return 0; }
EXPORT fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return 0; }
EXPORT fmi2Status fmi2Reset(fmi2Component c) { (void)c; return 0; }
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)c; (void)on; (void)n; (void)cats; return 0; }
EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
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
EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
#ifdef ME
    outputs(c);
#endif
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; v[i] = *p; }
    return 0;
}
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    Pd *pd = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) pd->fault = v[i];
        else if (vr[i] == VR_FAULT_TICK) pd->fault_tick = v[i];
        else return 3;
    }
    return 0;
}
EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)c; (void)vr; for (size_t i = 0; i < n; i++) v[i] = 0; return 0; }
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)c; (void)vr; (void)n; (void)v; return 3; }
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)c; (void)vr; (void)n; (void)v; return 3; }
#ifndef ME
EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    (void)t; (void)no_prior;
    return step(c, h);
}
#else
EXPORT fmi2Status fmi2SetTime(fmi2Component c, fmi2Real t) { ((Pd *)c)->time = t; return 0; }
EXPORT fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t n) {
    Pd *pd = c; if (n != AXES) return 3; memcpy(pd->x, x, sizeof pd->x); return 0; }
EXPORT fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t n) {
    Pd *pd = c; if (n != AXES) return 3; memcpy(x, pd->x, sizeof pd->x); return 0; }
EXPORT fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real dx[], size_t n) {
    Pd *pd = c;
    if (n != AXES) return 3;
    for (int k = 0; k < AXES; k++) dx[k] = (pd->u[k] - pd->x[k]) / pd->tau;
    return 0;
}
EXPORT fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real z[], size_t n) { (void)c; (void)z; (void)n; return 0; }
EXPORT fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean no_prior, fmi2Boolean *enter,
                                               fmi2Boolean *terminate) {
    Pd *pd = c; (void)no_prior;
    *enter = 0; *terminate = 0;
    int s = misbehave(pd);
    pd->ticks++;
    return s;
}
EXPORT fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return 0; }
EXPORT fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info) {
    (void)c; memset(info, 0, sizeof *info); return 0; }
EXPORT fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return 0; }
#endif
#endif

#if FMI == 3
#ifdef FMI_HEADERS
#include "fmi3Functions.h"
#else
#include <stdint.h>
typedef void *fmi3Instance;
typedef void *fmi3InstanceEnvironment;
typedef const char *fmi3String;
typedef double fmi3Float64;
typedef int32_t fmi3Int32;
typedef bool fmi3Boolean;
typedef uint32_t fmi3ValueReference;
typedef int fmi3Status;
typedef void (*fmi3LogMessageCallback)(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);
typedef void (*fmi3IntermediateUpdateCallback)(fmi3InstanceEnvironment, fmi3Float64, fmi3Boolean, fmi3Boolean,
                                               fmi3Boolean, fmi3Boolean, fmi3Boolean *, fmi3Float64 *);
#endif

EXPORT const char *fmi3GetVersion(void) { return "3.0"; }
EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources,
        fmi3Boolean visible, fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,
        const fmi3ValueReference required[], size_t n_required, fmi3InstanceEnvironment env,
        fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback intermediate) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)event_mode;
    (void)early_return; (void)required; (void)n_required; (void)intermediate;
    Pd *c = create();
    if (c && log) log(env, 0, "logAll", "pd: instantiated (FMI 3.0)");
    return c;
}
EXPORT void fmi3FreeInstance(fmi3Instance c) { destroy(c); }
EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean a, fmi3Float64 b, fmi3Float64 d, fmi3Boolean e,
                                              fmi3Float64 g) {
    (void)c; (void)a; (void)b; (void)d; (void)e; (void)g; return 0; }
EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance c) { (void)c; return 0; }
EXPORT fmi3Status fmi3Terminate(fmi3Instance c) { (void)c; return 0; }
EXPORT fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Float64 v[], size_t nv) {
    (void)nv;
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; *p = v[i]; }
    return 0;
}
EXPORT fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[], size_t nv) {
    (void)nv;
    for (size_t i = 0; i < n; i++) { double *p = real_of(c, vr[i]); if (!p) return 3; v[i] = *p; }
    return 0;
}
EXPORT fmi3Status fmi3SetInt32(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv) {
    Pd *pd = c; (void)nv;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == VR_FAULT) pd->fault = v[i];
        else if (vr[i] == VR_FAULT_TICK) pd->fault_tick = v[i];
        else return 3;
    }
    return 0;
}
EXPORT fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Boolean v[], size_t nv) {
    (void)c; (void)vr; (void)n; (void)v; (void)nv; return 3; }
EXPORT fmi3Status fmi3SetString(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3String v[], size_t nv) {
    (void)c; (void)vr; (void)n; (void)v; (void)nv; return 3; }
EXPORT fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_prior,
                             fmi3Boolean *event, fmi3Boolean *terminate, fmi3Boolean *early, fmi3Float64 *last) {
    (void)no_prior;
    *event = false; *terminate = false; *early = false; *last = t + h;
    return step(c, h);
}
#endif
