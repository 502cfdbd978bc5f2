#pragma once
// The oracle of every fuzz target: a broken promise of the parser under test
// prints what was promised and aborts, so libFuzzer (and the corpus replay
// test) report it as a crash with the input that caused it. Refusals of bad
// input are the expected outcome and never reach here.

#include <cstdio>
#include <cstdlib>

namespace cdpr::fuzz {

inline void require(bool promise_kept, const char* promise) {
  if (promise_kept) return;
  std::fprintf(stderr, "fuzz: broken promise: %s\n", promise);
  std::abort();
}

}  // namespace cdpr::fuzz
