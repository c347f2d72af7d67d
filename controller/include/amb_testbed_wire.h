/*
 * amb_testbed_wire.h: the plant <-> controller wire protocol of the AMB
 * touchdown testbed, version 4, for controllers written in C or C++.
 *
 * The source of truth is controller/src/wire.rs; docs/wire-protocol.md is
 * the long form (services, handshake, wake protocol, liveness, the exact
 * floating-point form of the shipped laws, the history of the versions).
 * Every size and offset below is checked at compile time, and
 * tests/tests/controllers.rs reads this header (every #define and every
 * struct field), compiles a program with it, and compares each constant,
 * size and offset with the Rust definitions (controller::wire::constants and
 * layouts), naming any difference.
 *
 * All structs: native endianness (both processes run on one machine),
 * double = IEEE 754 binary64, text UTF-8 padded with NUL bytes, no padding
 * bytes anywhere, alignment 8. iceoryx2: publish-subscribe services of the
 * "ipc" service variant, payload type details "fixed size" with the type
 * names below (AMB_TESTBED_*_TYPE_NAME), sizeof and alignof the struct, and
 * no user header (the binding's default). C11 or C++11 or later.
 */
#ifndef AMB_TESTBED_WIRE_H
#define AMB_TESTBED_WIRE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define AMB_TESTBED_STATIC_ASSERT static_assert
#define AMB_TESTBED_ALIGNOF alignof
extern "C" {
#else
#define AMB_TESTBED_STATIC_ASSERT _Static_assert
#define AMB_TESTBED_ALIGNOF _Alignof
#endif

/* Protocol version; also in every iceoryx2 type name (a peer of another
 * version cannot open this version's services). */
#define AMB_TESTBED_PROTOCOL_VERSION 4u
/* Room for axes in a frame; `axes` says how many entries are used. */
#define AMB_TESTBED_MAX_AXES 8
/* Axes of the planar model (x, y) and of the two-plane rotor (x_A, y_A, x_B,
 * y_B): Hello.axes is one of them. A controller that drives only the planar
 * model refuses a 4-axis hello with AMB_TESTBED_ACK_AXES. */
#define AMB_TESTBED_AXES 2u
#define AMB_TESTBED_TWO_PLANE_AXES 4u
/* Units code: V, A, s, N, m, kg. */
#define AMB_TESTBED_UNITS_SI 1u
#define AMB_TESTBED_RUN_ID_LEN 32
#define AMB_TESTBED_LAW_NAME_LEN 32
#define AMB_TESTBED_MESSAGE_LEN 256
#define AMB_TESTBED_PARAMS_LEN 4096
#define AMB_TESTBED_OVERRIDES_LEN 4096

/* Service and node names: AMB_TESTBED_SERVICE_PREFIX "/<run id>/<what>", e.g.
 * "amb-testbed/<id>/sensor"; nodes "amb-testbed/<id>/plant" and ".../controller". */
#define AMB_TESTBED_SERVICE_PREFIX "amb-testbed"

/* iceoryx2 payload type names. */
#define AMB_TESTBED_SENSOR_FRAME_TYPE_NAME "amb_testbed.v4.SensorFrame"
#define AMB_TESTBED_COMMAND_FRAME_TYPE_NAME "amb_testbed.v4.CommandFrame"
#define AMB_TESTBED_WAKE_REQUEST_TYPE_NAME "amb_testbed.v4.WakeRequest"
#define AMB_TESTBED_HELLO_TYPE_NAME "amb_testbed.v4.Hello"
#define AMB_TESTBED_ACK_TYPE_NAME "amb_testbed.v4.Ack"

/* SensorFrame.status: the run is over; exit 0 (seq and values carry no sample). */
#define AMB_TESTBED_SENSOR_STOP 1u
/* CommandFrame.status: the controller got SIGINT/SIGTERM and is exiting. */
#define AMB_TESTBED_COMMAND_STOPPING 1u

/* Hello.mode */
#define AMB_TESTBED_MODE_LOCKSTEP 1u
#define AMB_TESTBED_MODE_REALTIME 2u
#define AMB_TESTBED_MODE_BENCH 3u

/* Ack.status: 0 accepted, else why the hello is refused. */
#define AMB_TESTBED_ACK_ACCEPTED 0u
#define AMB_TESTBED_ACK_VERSION 1u
#define AMB_TESTBED_ACK_RATE 2u
#define AMB_TESTBED_ACK_AXES 3u
#define AMB_TESTBED_ACK_UNITS 4u
#define AMB_TESTBED_ACK_LAW 5u
#define AMB_TESTBED_ACK_RUN_ID 6u
#define AMB_TESTBED_ACK_PARAMS 7u

/* One sample of the sensors with the keyphasor, plant -> controller (service <id>/sensor). 128 bytes. */
typedef struct amb_testbed_SensorFrame {
    uint64_t seq; /* tick index k (0, 1, 2, ...) */
    double t_s; /* simulated time of the sample, k T (s) */
    uint64_t token; /* the run's token (Hello.token); another token: ignore the frame */
    uint64_t sent_ns; /* plant's CLOCK_MONOTONIC at publish (ns) */
    uint32_t status; /* bit 0: AMB_TESTBED_SENSOR_STOP */
    uint32_t session; /* handshake session (Hello.session) */
    uint32_t axes; /* entries of sensor_v in use (Hello.axes: 2 or 4) */
    uint32_t reserved; /* 0 */
    double sensor_v[AMB_TESTBED_MAX_AXES]; /* sensor voltages A_s * delta (V): x, y or x_A, y_A, x_B, y_B; unused entries 0 */
    double speed_rad_s; /* keyphasor: the rotor's spin speed (rad/s) */
    double angle_rad; /* keyphasor: the rotor's angle (rad) in [0, 2 pi); 0 when the unbalance points along +x */
} amb_testbed_SensorFrame;

/* The answer to one sample, controller -> plant (service <id>/command). 112 bytes. */
typedef struct amb_testbed_CommandFrame {
    uint64_t seq; /* the seq of the SensorFrame answered */
    uint64_t token; /* the run's token, copied from the hello */
    uint64_t received_ns; /* controller's CLOCK_MONOTONIC when it took the sensor frame (ns) */
    uint64_t sent_ns; /* controller's CLOCK_MONOTONIC at publish (ns) */
    uint32_t status; /* 0, or AMB_TESTBED_COMMAND_STOPPING */
    uint32_t session; /* handshake session (Hello.session) */
    uint32_t axes; /* entries of current_a in use (Hello.axes) */
    uint32_t reserved; /* 0 */
    double current_a[AMB_TESTBED_MAX_AXES]; /* coil currents (A) in axis order, each saturated at its plane's limit (current_limit_a, b_current_limit_a); unused entries 0 */
} amb_testbed_CommandFrame;

/* "Notify me before I block" (services <id>/sensor/wake and <id>/command/wake). 8 bytes. */
typedef struct amb_testbed_WakeRequest {
    uint64_t seq; /* informative */
} amb_testbed_WakeRequest;

/* The plant's side of the handshake (service <id>/hello). 4448 bytes. Plane A
 * (the planar model's plane) in the fields of version 3, plane B and the
 * rotor's geometry after params (0 on a planar hello). */
typedef struct amb_testbed_Hello {
    uint32_t protocol_version; /* AMB_TESTBED_PROTOCOL_VERSION */
    uint32_t axes; /* AMB_TESTBED_AXES or AMB_TESTBED_TWO_PLANE_AXES */
    uint32_t units; /* AMB_TESTBED_UNITS_SI */
    uint32_t session; /* 1, +1 per reconnection */
    uint64_t token; /* the run's token: random, never 0 */
    double rate_hz; /* controller rate (Hz) */
    double period_s; /* T = 1 / rate_hz as the plant computed it (s) */
    char run_id[AMB_TESTBED_RUN_ID_LEN]; /* run id, UTF-8, NUL-padded (not terminated when 32 bytes long) */
    char law[AMB_TESTBED_LAW_NAME_LEN]; /* law name (controller.law), UTF-8, NUL-padded */
    double stiffness_n_per_m; /* design k_e (N/m) */
    double damping_ratio; /* design xi_e */
    double ki_n_per_a; /* k_i (N/A) */
    double ks_n_per_m; /* k_s (N/m) */
    double amp_gain_a_per_v; /* A_a (A/V) */
    double sensor_gain_v_per_m; /* A_s (V/m) */
    double rotor_mass_kg; /* m_r (kg): the mass this bearing carries */
    double gravity_m_s2; /* g (m/s^2) */
    double current_limit_a; /* i_max (A): saturate the currents at it */
    double air_gap_m; /* touchdown air gap r_0 (m) */
    uint32_t delay_samples; /* the plant applies the command of sample k from tick k + d */
    uint32_t gravity_bias; /* 1: add the bias m_r g / k_i on y */
    uint64_t spin_ns; /* busy-poll budget before blocking (ns) */
    uint32_t mode; /* AMB_TESTBED_MODE_* */
    uint32_t plant_pid; /* informative */
    uint32_t params_len; /* bytes of params in use */
    uint32_t reserved; /* 0 */
    char params[AMB_TESTBED_PARAMS_LEN]; /* the law's parameters: [controller.params] as TOML text, UTF-8, not NUL-terminated */
    double b_stiffness_n_per_m; /* plane B: design k_e (N/m) */
    double b_damping_ratio; /* plane B: design xi_e */
    double b_ki_n_per_a; /* plane B: k_i (N/A) */
    double b_ks_n_per_m; /* plane B: k_s (N/m) */
    double b_amp_gain_a_per_v; /* plane B: A_a (A/V) */
    double b_sensor_gain_v_per_m; /* plane B: A_s (V/m) */
    double b_rotor_mass_kg; /* plane B: the mass it carries (kg) */
    double b_current_limit_a; /* plane B: i_max (A) */
    double b_air_gap_m; /* plane B: touchdown air gap (m) */
    double total_mass_kg; /* the whole rotor's mass M (kg) */
    double transverse_inertia_kg_m2; /* I_t about the centre of mass (kg m^2) */
    double polar_inertia_kg_m2; /* I_p (kg m^2) */
    double rated_speed_rad_s; /* rated spin speed (rad/s) */
    double bearing_a_z_m; /* station of bearing A from the centre of mass along z (m), < bearing_b_z_m */
    double bearing_b_z_m; /* station of bearing B (m) */
    double sensor_a_z_m; /* station of sensor A (m) */
    double sensor_b_z_m; /* station of sensor B (m) */
} amb_testbed_Hello;

/* The controller's answer to a hello (service <id>/ack). 4416 bytes. */
typedef struct amb_testbed_Ack {
    uint32_t protocol_version; /* AMB_TESTBED_PROTOCOL_VERSION */
    uint32_t session; /* the Hello.session answered */
    uint32_t status; /* AMB_TESTBED_ACK_* (0 accepted) */
    uint32_t controller_pid; /* informative */
    uint64_t token; /* echo of Hello.token */
    char law[AMB_TESTBED_LAW_NAME_LEN]; /* the law actually run, UTF-8, NUL-padded */
    char message[AMB_TESTBED_MESSAGE_LEN]; /* what it runs, or why it refuses, UTF-8, NUL-padded */
    uint32_t overrides_len; /* bytes of overrides in use */
    uint32_t reserved; /* 0 */
    char overrides[AMB_TESTBED_OVERRIDES_LEN]; /* TOML text: a [controller] table of what the controller runs differently from the hello; empty if nothing */
} amb_testbed_Ack;

/* The layout, checked by the compiler. */
AMB_TESTBED_STATIC_ASSERT(sizeof(amb_testbed_SensorFrame) == 128, "SensorFrame: 128 bytes");
AMB_TESTBED_STATIC_ASSERT(AMB_TESTBED_ALIGNOF(amb_testbed_SensorFrame) == 8, "SensorFrame: alignment 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, seq) == 0, "SensorFrame.seq at 0");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, t_s) == 8, "SensorFrame.t_s at 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, token) == 16, "SensorFrame.token at 16");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, sent_ns) == 24, "SensorFrame.sent_ns at 24");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, status) == 32, "SensorFrame.status at 32");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, session) == 36, "SensorFrame.session at 36");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, axes) == 40, "SensorFrame.axes at 40");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, reserved) == 44, "SensorFrame.reserved at 44");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, sensor_v) == 48, "SensorFrame.sensor_v at 48");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, speed_rad_s) == 112, "SensorFrame.speed_rad_s at 112");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_SensorFrame, angle_rad) == 120, "SensorFrame.angle_rad at 120");
AMB_TESTBED_STATIC_ASSERT(sizeof(amb_testbed_CommandFrame) == 112, "CommandFrame: 112 bytes");
AMB_TESTBED_STATIC_ASSERT(AMB_TESTBED_ALIGNOF(amb_testbed_CommandFrame) == 8, "CommandFrame: alignment 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, seq) == 0, "CommandFrame.seq at 0");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, token) == 8, "CommandFrame.token at 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, received_ns) == 16, "CommandFrame.received_ns at 16");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, sent_ns) == 24, "CommandFrame.sent_ns at 24");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, status) == 32, "CommandFrame.status at 32");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, session) == 36, "CommandFrame.session at 36");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, axes) == 40, "CommandFrame.axes at 40");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, reserved) == 44, "CommandFrame.reserved at 44");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_CommandFrame, current_a) == 48, "CommandFrame.current_a at 48");
AMB_TESTBED_STATIC_ASSERT(sizeof(amb_testbed_WakeRequest) == 8, "WakeRequest: 8 bytes");
AMB_TESTBED_STATIC_ASSERT(AMB_TESTBED_ALIGNOF(amb_testbed_WakeRequest) == 8, "WakeRequest: alignment 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_WakeRequest, seq) == 0, "WakeRequest.seq at 0");
AMB_TESTBED_STATIC_ASSERT(sizeof(amb_testbed_Hello) == 4448, "Hello: 4448 bytes");
AMB_TESTBED_STATIC_ASSERT(AMB_TESTBED_ALIGNOF(amb_testbed_Hello) == 8, "Hello: alignment 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, protocol_version) == 0, "Hello.protocol_version at 0");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, axes) == 4, "Hello.axes at 4");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, units) == 8, "Hello.units at 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, session) == 12, "Hello.session at 12");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, token) == 16, "Hello.token at 16");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, rate_hz) == 24, "Hello.rate_hz at 24");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, period_s) == 32, "Hello.period_s at 32");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, run_id) == 40, "Hello.run_id at 40");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, law) == 72, "Hello.law at 72");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, stiffness_n_per_m) == 104, "Hello.stiffness_n_per_m at 104");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, damping_ratio) == 112, "Hello.damping_ratio at 112");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, ki_n_per_a) == 120, "Hello.ki_n_per_a at 120");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, ks_n_per_m) == 128, "Hello.ks_n_per_m at 128");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, amp_gain_a_per_v) == 136, "Hello.amp_gain_a_per_v at 136");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, sensor_gain_v_per_m) == 144, "Hello.sensor_gain_v_per_m at 144");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, rotor_mass_kg) == 152, "Hello.rotor_mass_kg at 152");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, gravity_m_s2) == 160, "Hello.gravity_m_s2 at 160");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, current_limit_a) == 168, "Hello.current_limit_a at 168");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, air_gap_m) == 176, "Hello.air_gap_m at 176");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, delay_samples) == 184, "Hello.delay_samples at 184");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, gravity_bias) == 188, "Hello.gravity_bias at 188");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, spin_ns) == 192, "Hello.spin_ns at 192");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, mode) == 200, "Hello.mode at 200");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, plant_pid) == 204, "Hello.plant_pid at 204");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, params_len) == 208, "Hello.params_len at 208");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, reserved) == 212, "Hello.reserved at 212");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, params) == 216, "Hello.params at 216");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_stiffness_n_per_m) == 4312, "Hello.b_stiffness_n_per_m at 4312");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_damping_ratio) == 4320, "Hello.b_damping_ratio at 4320");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_ki_n_per_a) == 4328, "Hello.b_ki_n_per_a at 4328");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_ks_n_per_m) == 4336, "Hello.b_ks_n_per_m at 4336");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_amp_gain_a_per_v) == 4344, "Hello.b_amp_gain_a_per_v at 4344");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_sensor_gain_v_per_m) == 4352, "Hello.b_sensor_gain_v_per_m at 4352");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_rotor_mass_kg) == 4360, "Hello.b_rotor_mass_kg at 4360");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_current_limit_a) == 4368, "Hello.b_current_limit_a at 4368");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, b_air_gap_m) == 4376, "Hello.b_air_gap_m at 4376");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, total_mass_kg) == 4384, "Hello.total_mass_kg at 4384");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, transverse_inertia_kg_m2) == 4392, "Hello.transverse_inertia_kg_m2 at 4392");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, polar_inertia_kg_m2) == 4400, "Hello.polar_inertia_kg_m2 at 4400");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, rated_speed_rad_s) == 4408, "Hello.rated_speed_rad_s at 4408");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, bearing_a_z_m) == 4416, "Hello.bearing_a_z_m at 4416");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, bearing_b_z_m) == 4424, "Hello.bearing_b_z_m at 4424");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, sensor_a_z_m) == 4432, "Hello.sensor_a_z_m at 4432");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Hello, sensor_b_z_m) == 4440, "Hello.sensor_b_z_m at 4440");
AMB_TESTBED_STATIC_ASSERT(sizeof(amb_testbed_Ack) == 4416, "Ack: 4416 bytes");
AMB_TESTBED_STATIC_ASSERT(AMB_TESTBED_ALIGNOF(amb_testbed_Ack) == 8, "Ack: alignment 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, protocol_version) == 0, "Ack.protocol_version at 0");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, session) == 4, "Ack.session at 4");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, status) == 8, "Ack.status at 8");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, controller_pid) == 12, "Ack.controller_pid at 12");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, token) == 16, "Ack.token at 16");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, law) == 24, "Ack.law at 24");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, message) == 56, "Ack.message at 56");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, overrides_len) == 312, "Ack.overrides_len at 312");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, reserved) == 316, "Ack.reserved at 316");
AMB_TESTBED_STATIC_ASSERT(offsetof(amb_testbed_Ack, overrides) == 320, "Ack.overrides at 320");

#ifdef __cplusplus
}
#endif

#endif /* AMB_TESTBED_WIRE_H */
