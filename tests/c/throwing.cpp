// throwing.cpp: a C++ law whose update throws at sample 100 (tests/tests/c_api.rs). An
// exception must not cross into the library: the process aborts, with Rust's message.
#include <stdexcept>

#include "amb_testbed_controller.h"

namespace {
int state = 0;
void *build(void *, const amb_design *, amb_params *, char *, size_t) { return &state; }
void update(void *, const amb_sample *s, double *current_a) {
    if (s->seq >= 100) {
        throw std::runtime_error("throwing: a C++ exception in update");
    }
    current_a[0] = 0.0;
    current_a[1] = 0.0;
}
void reset(void *) {}
void drop(void *) {}
} // namespace

int main(int argc, char **argv) {
    amb_law law{};
    law.abi_version = AMB_CONTROLLER_ABI_VERSION;
    law.name = "faulty"; // the tests run every faulty law under one name
    law.build = build;
    law.update = update;
    law.reset = reset;
    law.drop = drop;
    return amb_serve(&law, 1, argc, argv);
}
