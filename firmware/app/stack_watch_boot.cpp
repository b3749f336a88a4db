// firmware/app/stack_watch_boot.cpp: the stack painted at boot, before the
// static constructors (stack_watch.hpp), in every image that reads its mark:
// linked into each as a source of its own, so the registration is written
// once. .preinit_array runs before .init_array (picolibc's crt0), and the
// linker script keeps the section whole.
#include "stack_watch.hpp"

namespace ascorr::app {
namespace {

__attribute__((section(".preinit_array"), used)) void (*const g_paint_at_boot)() = &stack_watch::paint;

}  // namespace
}  // namespace ascorr::app
