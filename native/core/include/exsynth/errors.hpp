#pragma once
// The engine's error hierarchy. Each class maps 1:1 to a Python exception in
// the bindings (InvalidInput -> InvalidInputError(ValueError), ...). Messages
// are written for the user: name the input and say what to change.
#include <stdexcept>
#include <string>

namespace exsynth {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An argument is malformed (shape, range, NaN, empty mesh, ...).
class InvalidInput : public Error {
 public:
  using Error::Error;
};

/// The job would need more memory than its budget; thrown before allocating.
class OverBudget : public Error {
 public:
  using Error::Error;
};

/// A file cannot be read or written (missing, unreadable, a folder, a full
/// disk); maps to an OSError in Python.
class IoError : public Error {
 public:
  using Error::Error;
};

/// The caller cancelled the job through its ExecContext.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
  using Error::Error;
};

}  // namespace exsynth
