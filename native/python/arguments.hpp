#pragma once
// Checked conversion of the module's scalar, string and array arguments.
//
// Every function of exsynth._native takes its arguments as py::object and
// converts them here, never through pybind11's own casters: a value pybind11
// cannot cast (-1 for an unsigned seed, 2**31 for an int, a string for a
// number, a list for an array) would otherwise fail overload resolution and
// raise a TypeError that prints the whole signature and every array passed.
// Here each failure is an InvalidInput (-> InvalidInputError, a ValueError)
// that names the argument, its valid range and the value given. The ranges
// are the core's where the core exports them (see the option headers).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "exsynth/exec_context.hpp"

namespace exsynth::py_bind {

namespace py = pybind11;

/// Parameter types of the bound functions: each takes any Python object (the
/// *_arg functions below check it) and only names the expected type in the
/// function's signature and docstring.
#define EXSYNTH_ANY_ARG(Type)                                       \
  struct Type : py::object {                                        \
    using py::object::object;                                       \
    static bool check_(py::handle h) { return h.ptr() != nullptr; } \
  }
EXSYNTH_ANY_ARG(IntArg);
EXSYNTH_ANY_ARG(RealArg);
EXSYNTH_ANY_ARG(BoolArg);
EXSYNTH_ANY_ARG(StrArg);
EXSYNTH_ANY_ARG(ArrayArg);
EXSYNTH_ANY_ARG(OptionalArrayArg);
EXSYNTH_ANY_ARG(Vec3Arg);
EXSYNTH_ANY_ARG(ContextArg);
EXSYNTH_ANY_ARG(PathArg);
EXSYNTH_ANY_ARG(GridsArg);
EXSYNTH_ANY_ARG(NamesArg);
#undef EXSYNTH_ANY_ARG

/// An integer (Python int or NumPy integer; not a float) in [lo, hi].
long long integer_arg(const py::handle& v, const std::string& name, long long lo, long long hi,
                      const std::string& unit = "");
inline int int_arg(const py::handle& v, const std::string& name, int lo, int hi, const std::string& unit = "") {
  return int(integer_arg(v, name, lo, hi, unit));
}

/// A seed: any integer in [0, 2**64 - 1].
std::uint64_t seed_arg(const py::handle& v, const std::string& name = "seed");

/// A memory budget in bytes, 0 = the default (kDefaultMemoryBudget); returns
/// the budget to use.
std::size_t memory_budget_arg(const py::handle& v, const std::string& name = "memory_budget");

/// Interval ends for real_arg.
enum class Ends { Closed, OpenLow, OpenHigh, Open };
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A finite real number (int, float, NumPy scalar) in [lo, hi] (or an open
/// end, see Ends); lo = -kInf / hi = kInf: unbounded on that side.
double real_arg(const py::handle& v, const std::string& name, double lo = -kInf, double hi = kInf,
                Ends ends = Ends::Closed, const std::string& unit = "");

/// True / False (also NumPy booleans and the integers 0 and 1).
bool bool_arg(const py::handle& v, const std::string& name);

/// A str; `expected` says what it should name (e.g. "'spikes', 'pits' or 'holes'").
std::string string_arg(const py::handle& v, const std::string& name, const std::string& expected);

/// A file path: str or os.PathLike.
std::string path_arg(const py::handle& v, const std::string& name);

/// A list or tuple of str (a single str is one name).
std::vector<std::string> string_list_arg(const py::handle& v, const std::string& name);

/// A NumPy array, or anything NumPy turns into a numeric array (nested
/// lists / tuples of numbers); `expected` describes the wanted shape and dtype.
py::array array_arg(const py::handle& v, const std::string& name, const std::string& expected);

/// None -> nullptr, an ExecContext -> it.
ExecContext* context_arg(const py::handle& v, const std::string& name = "ctx");

/// A dict (for keyword collections such as write_vdb's grids).
py::dict dict_arg(const py::handle& v, const std::string& name, const std::string& expected);

/// Functions with fixed options also take **extra, so a misspelt keyword
/// is an InvalidInputError naming it and the options instead of pybind11's
/// signature dump (which prints every array passed).
void reject_unknown(const py::kwargs& extra, const std::string& options);

/// repr(v), shortened to a line, for messages.
std::string short_repr(const py::handle& v);

}  // namespace exsynth::py_bind

namespace pybind11::detail {
#define EXSYNTH_ARG_NAME(Type, text) \
  template <>                        \
  struct handle_type_name<exsynth::py_bind::Type> { static constexpr auto name = const_name(text); }
EXSYNTH_ARG_NAME(IntArg, "int");
EXSYNTH_ARG_NAME(RealArg, "float");
EXSYNTH_ARG_NAME(BoolArg, "bool");
EXSYNTH_ARG_NAME(StrArg, "str");
EXSYNTH_ARG_NAME(ArrayArg, "numpy.ndarray");
EXSYNTH_ARG_NAME(OptionalArrayArg, "numpy.ndarray | None");
EXSYNTH_ARG_NAME(Vec3Arg, "tuple[float, float, float]");
EXSYNTH_ARG_NAME(ContextArg, "ExecContext | None");
EXSYNTH_ARG_NAME(PathArg, "str | os.PathLike");
EXSYNTH_ARG_NAME(GridsArg, "dict[str, numpy.ndarray]");
EXSYNTH_ARG_NAME(NamesArg, "list[str] | None");
#undef EXSYNTH_ARG_NAME
}  // namespace pybind11::detail
