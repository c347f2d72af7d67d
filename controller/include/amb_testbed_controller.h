/*
 * amb_testbed_controller.h: a controller of the AMB touchdown testbed in C
 * (or C++, or any language that calls C), served by one call.
 *
 * A law is a struct of function pointers (amb_law): build it from the
 * plant's design and its parameters, update it on a sample into the coil
 * currents, reset it, drop it. amb_serve() is the whole controller process:
 * the command line (--run-id ID or AMB_TESTBED_RUN_ID, --law, --config,
 * --pin-core, --connect-timeout-s, --quiet), the run-id lock, the handshake
 * with the plant, the wake protocol, liveness, SIGINT/SIGTERM and the exit
 * codes, exactly as controller::serve for a Rust law. No iceoryx2 of your
 * own: libamb_testbed_controller (.so or .a) holds it.
 *
 *   cargo build --release
 *   cc -std=c11 -O2 -ffp-contract=off -Icontroller/include my_law.c \
 *      target/release/libamb_testbed_controller.a -lgcc_s -lutil -lrt -lpthread -lm -ldl -lc -o my-law
 *   target/release/plant run config/cosim-10g.toml --set 'controller.command=["./my-law"]'
 *
 * The source of truth is controller/c/src/lib.rs; tests/tests/c_api.rs
 * compiles a program with this header and compares every size and offset
 * with the Rust definitions, and builds and runs examples/c and examples/cpp.
 * The functions of a law must not throw (C++: mark them noexcept or catch
 * inside): an exception that escapes one aborts the process. C11 or C++11.
 */
#ifndef AMB_TESTBED_CONTROLLER_H
#define AMB_TESTBED_CONTROLLER_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define AMB_CONTROLLER_STATIC_ASSERT static_assert
extern "C" {
#else
#define AMB_CONTROLLER_STATIC_ASSERT _Static_assert
#endif

/* The layout version of the structs below: put it in amb_law.abi_version. */
#define AMB_CONTROLLER_ABI_VERSION 1u
/* Room for axes in a sample and in the currents. */
#define AMB_MAX_AXES 8
/* Room for bearing planes in a design (two axes each). */
#define AMB_MAX_PLANES 4
/* Most laws one process serves. */
#define AMB_MAX_LAWS 16
/* Longest law name (bytes, without the NUL). */
#define AMB_MAX_NAME_LEN 31

/* amb_params_number's range checks. */
#define AMB_CHECK_FINITE 0u
#define AMB_CHECK_POSITIVE 1u       /* finite and > 0 */
#define AMB_CHECK_NON_NEGATIVE 2u   /* finite and >= 0 */
#define AMB_CHECK_BETWEEN 3u        /* finite and strictly between lo and hi */

/* amb_serve's exit codes. */
#define AMB_EXIT_OK 0            /* the plant ended the run */
#define AMB_EXIT_IO 1            /* an IPC failure */
#define AMB_EXIT_BAD_INPUT 2     /* arguments, a refused hello, a bad law table, a run id in use */
#define AMB_EXIT_PLANT_LOST 4    /* the plant is gone, or never said hello */
#define AMB_EXIT_INTERRUPTED 130 /* SIGINT or SIGTERM (the plant was told) */

/* The plant's constants of one bearing plane (SI). */
typedef struct amb_loop_constants {
    double ki_n_per_a;          /* force-current coefficient k_i (N/A) */
    double ks_n_per_m;          /* negative stiffness k_s (N/m) */
    double amp_gain_a_per_v;    /* amplifier gain A_a (A/V) */
    double sensor_gain_v_per_m; /* sensor gain A_s (V/m) */
    double rotor_mass_kg;       /* m_r (kg) */
    double gravity_m_s2;        /* g (m/s^2); the gravity bias is m_r g / k_i on y */
    double air_gap_m;           /* touchdown air gap r_0 (m) */
} amb_loop_constants;

/* One bearing plane's design: the closed loop asked for and the plant's constants. */
typedef struct amb_plane_design {
    double stiffness_n_per_m;    /* closed-loop stiffness k_e (N/m) */
    double damping_ratio;        /* closed-loop damping ratio xi_e */
    double current_limit_a;      /* amplifier limit i_max (A): amb_serve saturates at it */
    uint32_t gravity_bias;       /* 1: the bias m_r g / k_i on y */
    uint32_t reserved;           /* 0 */
    amb_loop_constants constants;
} amb_plane_design;

/* The rigid rotor of the two-plane model; 0 on the planar model. */
typedef struct amb_geometry {
    double mass_kg;                  /* rotor mass M (kg) */
    double transverse_inertia_kg_m2; /* I_t about the centre of mass (kg m^2) */
    double polar_inertia_kg_m2;      /* I_p (kg m^2) */
    double rated_speed_rad_s;        /* rated spin speed (rad/s) */
    double bearing_z_m[2];           /* axial stations of bearings A, B from the centre of mass (m) */
    double sensor_z_m[2];            /* axial stations of sensors A, B (m) */
} amb_geometry;

/* The design a law is built from. A law gets every axis at once: it drives the planar model
 * (2 axes, one plane) and the two-plane rotor (4 axes: x, y at bearing A, then at B) alike,
 * or refuses the one it cannot (build returns NULL with a message). */
typedef struct amb_design {
    uint32_t axes;          /* axes the law drives: 2 (x, y) or 4 (x_A, y_A, x_B, y_B) */
    uint32_t planes;        /* entries of plane[] in use: 1 or 2 */
    uint32_t delay_samples; /* the command of sample k is applied from tick k + delay_samples */
    uint32_t reserved;      /* 0 */
    double period_s;        /* sampling period T (s), as the plant computed it */
    amb_plane_design plane[AMB_MAX_PLANES];
    amb_geometry geometry;  /* the two-plane rotor's; 0 on the planar model */
} amb_design;

/* One controller input. */
typedef struct amb_sample {
    uint64_t seq;                    /* sample index k */
    double t_s;                      /* simulated time of the sample (s) */
    uint32_t axes;                   /* entries of sensor_v in use: 2 (x, y) or 4 (x_A, y_A, x_B, y_B) */
    uint32_t reserved;               /* 0 */
    double sensor_v[AMB_MAX_AXES];   /* sensor voltages A_s * displacement (V); the rest 0 */
    double speed_rad_s;              /* the rotor's spin speed (rad/s): the keyphasor */
    double angle_rad;                /* the rotor's angle (rad) in [0, 2 pi): the keyphasor (0: unbalance along +x) */
} amb_sample;

/* The parameter reader handed to build (opaque). */
typedef struct amb_params amb_params;

/* A law. Every function must be set; they are called from one thread. */
typedef struct amb_law {
    uint32_t abi_version; /* AMB_CONTROLLER_ABI_VERSION */
    uint32_t reserved;    /* 0 */
    const char *name;     /* the scene's controller.law (UTF-8, at most AMB_MAX_NAME_LEN bytes) */
    const char *summary;  /* one line, or NULL */
    void *context;        /* handed to build, or NULL */
    /* The law's state from the design and its parameters (read them with amb_params_*), or
     * NULL to refuse: after a getter returned -1, or with a message in error (error_len bytes
     * with the NUL). A refusal ends the run before it starts (the plant exits 2 with it). */
    void *(*build)(void *context, const amb_design *design, amb_params *params, char *error, size_t error_len);
    /* The coil currents (A) for a sample: sample->axes entries into current_a (room for
     * AMB_MAX_AXES, zeroed), before the amplifier limits (each plane's). A non-finite current is sent as NaN:
     * the plant holds the last valid one and ends the run past its budget (exit 8). */
    void (*update)(void *law, const amb_sample *sample, double *current_a);
    /* Forget all memory (back to the state before the first sample). */
    void (*reset)(void *law);
    /* Free the state build returned. */
    void (*drop)(void *law);
} amb_law;

/* The whole controller process for laws[0..count). argv as main got it (NULL: the process's
 * own). Returns the exit code for main to return (AMB_EXIT_*); --help and --version print and
 * exit. Once per process. A bad table (a NULL function, a bad name, another ABI version) is
 * refused with a message naming the law and the field: AMB_EXIT_BAD_INPUT. */
int amb_serve(const amb_law *laws, size_t count, int argc, char **argv);

/* The library's AMB_CONTROLLER_ABI_VERSION. */
uint32_t amb_abi_version(void);

/* In build: the number at key (unit: "" or NULL when dimensionless) into *value, default_value
 * when absent, checked (AMB_CHECK_*; lo, hi for AMB_CHECK_BETWEEN; a default_value that fails
 * the check is refused too, as the law's fault). 0, or -1 when refused (return NULL from build:
 * the refusal names the law, the key, the value and the unit); a NULL value is refused. A key
 * build does not read is refused as unknown. */
int amb_params_number(amb_params *params, const char *key, const char *unit, double default_value,
                      uint32_t check, double lo, double hi, double *value);
/* In build: the boolean at key into *value (1 or 0), default_value when absent. 0 or -1 (also
 * for a NULL value). */
int amb_params_flag(amb_params *params, const char *key, int default_value, int *value);
/* In build: the parameters as TOML text (NUL-terminated, valid during build). */
const char *amb_params_text(amb_params *params);

/* The layout, checked (tests/tests/c_api.rs checks it against the Rust definitions too). */
AMB_CONTROLLER_STATIC_ASSERT(sizeof(amb_loop_constants) == 56, "amb_loop_constants");
AMB_CONTROLLER_STATIC_ASSERT(sizeof(amb_plane_design) == 88, "amb_plane_design");
AMB_CONTROLLER_STATIC_ASSERT(offsetof(amb_plane_design, constants) == 32, "amb_plane_design.constants");
AMB_CONTROLLER_STATIC_ASSERT(sizeof(amb_geometry) == 64, "amb_geometry");
AMB_CONTROLLER_STATIC_ASSERT(sizeof(amb_design) == 24 + 4 * 88 + 64, "amb_design");
AMB_CONTROLLER_STATIC_ASSERT(offsetof(amb_design, geometry) == 24 + 4 * 88, "amb_design.geometry");
AMB_CONTROLLER_STATIC_ASSERT(offsetof(amb_design, plane) == 24, "amb_design.plane");
AMB_CONTROLLER_STATIC_ASSERT(sizeof(amb_sample) == 104, "amb_sample");
AMB_CONTROLLER_STATIC_ASSERT(offsetof(amb_sample, sensor_v) == 24, "amb_sample.sensor_v");
AMB_CONTROLLER_STATIC_ASSERT(offsetof(amb_sample, speed_rad_s) == 88, "amb_sample.speed_rad_s");

#ifdef __cplusplus
}
#endif

#endif /* AMB_TESTBED_CONTROLLER_H */
