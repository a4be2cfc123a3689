#pragma once
// Errors that reach the user. Every message names where the problem is (file, key), the
// offending value and the rule it breaks, so that bad input can be fixed without reading code.
#include <stdexcept>
#include <string>
#include <vector>
#include <initializer_list>

namespace oobleck {

/// Bad user input: a file, key or value that breaks a stated rule. The CLI prints what() and
/// exits with status 2 before writing any output.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical failure inside a law or solver (non-convergence, NaN): the CLI exits with status 3.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Closest candidate to `word` among `candidates` (Levenshtein distance), or "" when nothing is
/// reasonably close. Used for "did you mean" suggestions on unknown keys and names.
std::string closest_match(const std::string& word, const std::initializer_list<std::string>& candidates);
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace oobleck
