# Test kinds. Every test carries exactly one label, and the time limit of
# its kind:
#   unit         one piece on its own, no process of ours besides the test;
#                `make check` runs these, all of them within seconds.
#   integration  the programs, the daemon and the virtual robot together.
#   slow         anything that takes long, whatever its kind: whole
#                calibrations, packaging. `make test` runs every kind.
# The limits leave room for a machine shared with other builds; the
# sanitizer build runs some times slower and gets twice as long.
set(CDPR_TEST_TIMEOUT_unit 60)
set(CDPR_TEST_TIMEOUT_integration 300)
set(CDPR_TEST_TIMEOUT_slow 900)
if(CDPR_SANITIZE)
  foreach(kind unit integration slow)
    math(EXPR CDPR_TEST_TIMEOUT_${kind} "${CDPR_TEST_TIMEOUT_${kind}} * 2")
  endforeach()
endif()

# cdpr_test_kind(<kind> <test>...): labels tests added with add_test().
function(cdpr_test_kind kind)
  set_tests_properties(${ARGN} PROPERTIES LABELS ${kind} TIMEOUT ${CDPR_TEST_TIMEOUT_${kind}})
endfunction()
