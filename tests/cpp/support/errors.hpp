#pragma once
// The message of the InvalidInput a call throws, for tests that check a bad
// input's error names the input: "no error" when it throws none.
#include <string>
#include <utility>

#include "exsynth/errors.hpp"

namespace exsynth::testing {

template <class Call>
std::string invalid_input_message(Call&& call) {
  try {
    std::forward<Call>(call)();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace exsynth::testing
