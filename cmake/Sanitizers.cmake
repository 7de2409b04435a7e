# MOCAP_SANITIZE: build everything under sanitizers (scripts/sanitize.sh).
#   address  AddressSanitizer (with LeakSanitizer) and UndefinedBehaviorSanitizer; with clang
#            also libFuzzer's coverage instrumentation, so the fuzzers in fuzz/ run on the
#            same libraries the tests check.
#   thread   ThreadSanitizer.
# Any report fails: UndefinedBehaviorSanitizer does not recover, and the test environment
# (scripts/sanitize.sh) makes every sanitizer exit non-zero. Reports that are not ours are
# suppressed in sanitizers/*.supp, one line each with the reason.
include_guard(GLOBAL)

set(MOCAP_SANITIZE "" CACHE STRING "Sanitizers to build with: address, thread, or empty")
set_property(CACHE MOCAP_SANITIZE PROPERTY STRINGS "" address thread)

set(MOCAP_LIBFUZZER OFF)
if(MOCAP_SANITIZE STREQUAL "address")
  # vptr is left out: plugins hide their symbols (mocap_add_plugin), so a type's typeinfo is
  # not unique across libraries and every virtual call between them would be reported.
  set(flags -fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all
            -fno-omit-frame-pointer)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    set(MOCAP_LIBFUZZER ON)
    list(APPEND flags -fsanitize=fuzzer-no-link)
  endif()
elseif(MOCAP_SANITIZE STREQUAL "thread")
  set(flags -fsanitize=thread -fno-omit-frame-pointer)
elseif(NOT MOCAP_SANITIZE STREQUAL "")
  message(FATAL_ERROR "MOCAP_SANITIZE=${MOCAP_SANITIZE}: use address, thread or leave it empty")
endif()
if(flags)
  add_compile_options(${flags})
  add_link_options(${flags})
endif()
