// pd.cpp: the testbed's `pd` law in C++, a class served by libamb_testbed_controller (here
// linked as the shared library). Its lockstep trace is the Rust pd's, byte for byte
// (tests/tests/c_api.rs). The functions handed to amb_serve are noexcept: an exception that
// escaped one would abort the process.
//
//   cargo build --release
//   c++ -std=c++17 -O2 -ffp-contract=off -Icontroller/include examples/cpp/pd.cpp
//       -Ltarget/release -lamb_testbed_controller -Wl,-rpath,$PWD/target/release -o pd-cpp
//   (one command line)
//   target/release/plant run config/cosim-10g.toml --set controller.law='"pd"' --set 'controller.command=["./pd-cpp"]'
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "amb_testbed_controller.h"

namespace {

// One bearing plane's PD, as PdGains::from_design (left to right) and SampledPd.
class PlanePd {
  public:
    PlanePd(const amb_plane_design &d, double period) : period_(period) {
        const amb_loop_constants &c = d.constants;
        const double loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        const double c_e = 2.0 * d.damping_ratio * std::sqrt(d.stiffness_n_per_m * c.rotor_mass_kg);
        kp_ = (d.stiffness_n_per_m + c.ks_n_per_m) / loop_gain;
        kd_ = c_e / loop_gain;
        amp_ = c.amp_gain_a_per_v;
        bias_ = {0.0, d.gravity_bias ? c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a : 0.0};
    }

    void update(const double *u, double *current_a) {
        for (int j = 0; j < 2; j++) {
            const double rate = has_previous_ ? (u[j] - previous_[j]) / period_ : 0.0;
            current_a[j] = bias_[j] - amp_ * (kp_ * u[j] + kd_ * rate);
            previous_[j] = u[j];
        }
        has_previous_ = true;
    }

    void reset() { has_previous_ = false; }

  private:
    double kp_ = 0.0, kd_ = 0.0, amp_ = 0.0, period_ = 0.0;
    std::array<double, 2> bias_{}, previous_{};
    bool has_previous_ = false;
};

// The law: one PD per plane (decentralised, as the registry's pd on a two-plane rotor).
class Pd {
  public:
    explicit Pd(const amb_design &design) {
        for (uint32_t p = 0; p < design.planes; p++) {
            planes_.emplace_back(design.plane[p], design.period_s);
        }
    }

    void update(const amb_sample &s, double *current_a) {
        for (std::size_t p = 0; p < planes_.size(); p++) {
            planes_[p].update(&s.sensor_v[2 * p], &current_a[2 * p]);
        }
    }

    void reset() {
        for (PlanePd &p : planes_) {
            p.reset();
        }
    }

  private:
    std::vector<PlanePd> planes_;
};

void *build(void *, const amb_design *design, amb_params *, char *error, size_t error_len) noexcept {
    if (design->planes < 1 || design->planes > AMB_MAX_PLANES || design->axes != 2 * design->planes) {
        std::snprintf(error, error_len, "drives 2 axes per plane, not %u axes", design->axes);
        return nullptr;
    }
    try {
        return new Pd(*design);
    } catch (...) { // std::bad_alloc: nothing may escape into the library
        std::snprintf(error, error_len, "out of memory");
        return nullptr;
    }
}

void update(void *law, const amb_sample *sample, double *current_a) noexcept {
    static_cast<Pd *>(law)->update(*sample, current_a);
}

void reset(void *law) noexcept { static_cast<Pd *>(law)->reset(); }

void drop(void *law) noexcept { delete static_cast<Pd *>(law); }

} // namespace

int main(int argc, char **argv) {
    amb_law law{};
    law.abi_version = AMB_CONTROLLER_ABI_VERSION;
    law.name = "pd";
    law.summary = "the design's PD, naively sampled, in C++";
    law.build = build;
    law.update = update;
    law.reset = reset;
    law.drop = drop;
    return amb_serve(&law, 1, argc, argv);
}
