// The fuzz build's own copy of toml++'s compiled part (fuzz builds only):
// the system library is not instrumented, so without this libFuzzer would
// see no coverage inside the TOML parser and ASan would not check it.
// Symbols defined in the executable take precedence over the shared
// library's, so every toml++ call of the parsers lands here.
//
// Built as Debian ships the library (gcc, NDEBUG: TOML_ASSERT and
// TOML_ASSUME are no-ops), so the fuzzers test the code the daemon runs.
// With assertions on, toml++ 3.3.0 aborts on table headers such as "[[[1]]]"
// or "[\x01]" (precondition of parse_key(), upstream PR marzer/tomlplusplus#301);
// the shipped build reports them as a parse error, which the corpus and
// tests/src/formats/damaged_input_test.cc keep checking.

#define TOML_ASSERT(expr) static_assert(true)
#define TOML_IMPLEMENTATION 1
#include <toml++/toml.h>
