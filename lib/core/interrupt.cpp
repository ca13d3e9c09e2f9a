#include "core/interrupt.h"

namespace rths {
namespace {
volatile std::sig_atomic_t g_interrupt_requested = 0;
}  // namespace

volatile std::sig_atomic_t* InterruptFlag() { return &g_interrupt_requested; }

}  // namespace rths
