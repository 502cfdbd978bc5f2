# Test kinds. Every test carries exactly one label, and the time limit of
# its kind:
#   unit         one piece on its own, no process of ours besides the test;
#                `make check` runs these, all of them within seconds.
#   integration  the programs, the daemon and the virtual robot together;
#                also unit binaries' replays of whole simulated
#                calibrations (CDPR_REPLAY_TESTS, tests/CMakeLists.txt).
#   slow         anything that takes long, whatever its kind: whole
#                calibrations, packaging. `make test` runs every kind.
# The limits leave room for a machine shared with other builds.
set(CDPR_TEST_TIMEOUT_unit 60)
set(CDPR_TEST_TIMEOUT_integration 300)
set(CDPR_TEST_TIMEOUT_slow 900)

# How many times slower than the normal build the code under test runs in
# this build: 1, or CDPR_TEST_SLOWDOWN_SANITIZE under ASan + UBSan (at -O1).
# The integration tests pass it on (CDPR_TEST_SLOWDOWN, tests/integration/
# slowdown.h): they run the daemon against the virtual robot in wall-clock
# time, and a sanitized thread that falls behind the robot's physics or the
# daemon's fault timeouts fails a run for its slowness, not for a fault. So
# that build runs the virtual robot that many times slower and stretches the
# timeouts and deadlines alike; every limit of the normal build is unchanged.
# The per-kind limits above stretch with it.
set(CDPR_TEST_SLOWDOWN_SANITIZE 3 CACHE STRING "Time multiplier of the integration tests under the sanitizers")
set(CDPR_TEST_SLOWDOWN 1)
if(CDPR_SANITIZE)
  set(CDPR_TEST_SLOWDOWN ${CDPR_TEST_SLOWDOWN_SANITIZE})
  foreach(kind unit integration slow)
    math(EXPR CDPR_TEST_TIMEOUT_${kind} "${CDPR_TEST_TIMEOUT_${kind}} * ${CDPR_TEST_SLOWDOWN}")
  endforeach()
endif()

# The order ctest -j starts them in (highest cost first) until it has timed
# them itself: the slow ones first, so that none of the long runs starts
# last and leaves the other core idle while it finishes.
set(CDPR_TEST_COST_unit 1)
set(CDPR_TEST_COST_integration 10)
set(CDPR_TEST_COST_slow 100)

# cdpr_test_kind(<kind> <test>...): labels tests added with add_test().
function(cdpr_test_kind kind)
  set_tests_properties(${ARGN} PROPERTIES LABELS ${kind} TIMEOUT ${CDPR_TEST_TIMEOUT_${kind}}
                       COST ${CDPR_TEST_COST_${kind}})
endfunction()
