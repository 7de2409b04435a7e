# Sourced by scripts/sanitize.sh and scripts/fuzz.sh: the sanitizers' options for every process
# a test starts (mocap_launch, mocap_topic, the plugins they load), with the suppressions of
# test/sanitizers/. A report makes the process exit non-zero, so the test that started it fails.
sanitizers="$(cd "$(dirname "${BASH_SOURCE[0]}")/../test/sanitizers" && pwd)"
# new_delete_type_mismatch=0: Fast DDS 2.9.1 deletes an object of 64 bytes as one of 56 in
# RTPSReader::~RTPSReader (every frame of the report is in libfastrtps.so.2.9; see
# test/sanitizers/README.md). ASan has no suppression file entry for this check.
# intercept_tls_get_addr=0: LeakSanitizer (clang 14) then scans no thread's dynamic TLS as
# such; with it, its tracer twice read a block at 0x1c78 / 0x1c90 while a process ended
# ("Tracer caught signal 11", the leak check aborted: test/sanitizers/README.md). The blocks are
# heap chunks found from each thread's TLS descriptor all the same.
export ASAN_OPTIONS="intercept_tls_get_addr=0:new_delete_type_mismatch=0:detect_leaks=1:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:print_suppressions=0"
export LSAN_OPTIONS="suppressions=$sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:suppressions=$sanitizers/ubsan.supp"
# ignore_noninstrumented_modules=1: Debian's Fast DDS and Cyclone DDS are not built with
# -fsanitize=thread, so ThreadSanitizer sees their memory and mutex calls but not the
# synchronization around them (test/sanitizers/README.md has what it reported).
export TSAN_OPTIONS="ignore_noninstrumented_modules=1:halt_on_error=0:exitcode=66:second_deadlock_stack=1:suppressions=$sanitizers/tsan.supp:print_suppressions=0"
unset sanitizers
