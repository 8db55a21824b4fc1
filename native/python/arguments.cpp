#include "arguments.hpp"

#include <cmath>
#include <cstdio>

#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"

namespace exsynth::py_bind {
namespace {

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string type_name(const py::handle& v) {
  return py::str(py::type::handle_of(v).attr("__name__")).cast<std::string>();
}

/// "2.5 (float)": what was given, for the end of a message.
std::string given(const py::handle& v) {
  if (v.is_none()) return "None";
  if (PyLong_Check(v.ptr()) && !PyBool_Check(v.ptr())) return short_repr(v);
  return short_repr(v) + " (" + type_name(v) + ")";
}

[[noreturn]] void fail(const std::string& name, const std::string& expected, const py::handle& v) {
  throw InvalidInput("'" + name + "' must be " + expected + ", got " + given(v));
}

std::string with_unit(const std::string& range, const std::string& unit) {
  return unit.empty() ? range : range + " (" + unit + ")";
}

std::string real_range(double lo, double hi, Ends ends) {
  const bool open_lo = ends == Ends::OpenLow || ends == Ends::Open;
  const bool open_hi = ends == Ends::OpenHigh || ends == Ends::Open;
  if (lo == -kInf && hi == kInf) return "a finite number";
  if (hi == kInf) return std::string("a finite number ") + (open_lo ? "> " : ">= ") + num(lo);
  if (lo == -kInf) return std::string("a finite number ") + (open_hi ? "< " : "<= ") + num(hi);
  return std::string("a number in ") + (open_lo ? "(" : "[") + num(lo) + ", " + num(hi) + (open_hi ? ")" : "]");
}

/// v as a Python int (via __index__: ints, NumPy integers), or null.
py::object as_index(const py::handle& v) {
  if (v.is_none() || PyFloat_Check(v.ptr())) return py::object();
  PyObject* i = PyNumber_Index(v.ptr());
  if (!i) {
    PyErr_Clear();
    return py::object();
  }
  return py::reinterpret_steal<py::object>(i);
}

}  // namespace

std::string short_repr(const py::handle& v) {
  if (py::isinstance<py::array>(v)) {
    const py::array a = py::reinterpret_borrow<py::array>(v);
    std::string s = "a " + py::str(a.dtype()).cast<std::string>() + " array of shape (";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
  }
  std::string s;
  try {
    s = py::repr(v).cast<std::string>();
  } catch (const py::error_already_set&) {
    s = "<" + type_name(v) + ">";
  }
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

long long integer_arg(const py::handle& v, const std::string& name, long long lo, long long hi,
                      const std::string& unit) {
  const std::string expected =
      with_unit("an integer between " + std::to_string(lo) + " and " + std::to_string(hi), unit);
  const py::object i = as_index(v);
  if (!i) fail(name, expected, v);
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow || x < lo || x > hi) fail(name, expected, v);
  return x;
}

std::uint64_t seed_arg(const py::handle& v, const std::string& name) {
  const char* expected = "an integer between 0 and 2**64 - 1 (18446744073709551615)";
  const py::object i = as_index(v);
  if (!i) fail(name, expected, v);
  const unsigned long long x = PyLong_AsUnsignedLongLong(i.ptr());  // OverflowError when < 0 or >= 2**64
  if (x == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
    PyErr_Clear();
    fail(name, expected, v);
  }
  return std::uint64_t(x);
}

std::size_t memory_budget_arg(const py::handle& v, const std::string& name) {
  // 2**62 bytes is far beyond any machine; the cap keeps estimates in range.
  constexpr long long kMax = 1LL << 62;
  const long long b = integer_arg(v, name, 0, kMax, "bytes; 0 = the default, " + format_bytes(double(kDefaultMemoryBudget)));
  return b ? std::size_t(b) : kDefaultMemoryBudget;
}

double real_arg(const py::handle& v, const std::string& name, double lo, double hi, Ends ends,
                const std::string& unit) {
  const std::string expected = with_unit(real_range(lo, hi, ends), unit);
  if (v.is_none() || PyUnicode_Check(v.ptr()) || PyBytes_Check(v.ptr())) fail(name, expected, v);
  const double x = PyFloat_AsDouble(v.ptr());
  if (x == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    fail(name, expected, v);
  }
  const bool open_lo = ends == Ends::OpenLow || ends == Ends::Open;
  const bool open_hi = ends == Ends::OpenHigh || ends == Ends::Open;
  const bool ok = std::isfinite(x) && (open_lo ? x > lo : x >= lo) && (open_hi ? x < hi : x <= hi);
  if (!ok) fail(name, expected, v);
  return x;
}

bool bool_arg(const py::handle& v, const std::string& name) {
  if (PyBool_Check(v.ptr())) return v.ptr() == Py_True;
  const py::object numpy_bool = py::module_::import("numpy").attr("bool_");
  if (py::isinstance(v, numpy_bool)) return v.cast<bool>();
  if (PyLong_Check(v.ptr())) {
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (!overflow && (x == 0 || x == 1)) return x == 1;
  }
  fail(name, "True or False", v);
}

std::string string_arg(const py::handle& v, const std::string& name, const std::string& expected) {
  if (!PyUnicode_Check(v.ptr())) fail(name, "a string: " + expected, v);
  return v.cast<std::string>();
}

std::string path_arg(const py::handle& v, const std::string& name) {
  if (PyUnicode_Check(v.ptr())) return v.cast<std::string>();
  PyObject* p = PyOS_FSPath(v.ptr());
  if (!p) {
    PyErr_Clear();
    fail(name, "a file path (str or pathlib.Path)", v);
  }
  const py::object path = py::reinterpret_steal<py::object>(p);
  if (!PyUnicode_Check(path.ptr())) fail(name, "a file path (str or pathlib.Path)", v);
  return path.cast<std::string>();
}

std::vector<std::string> string_list_arg(const py::handle& v, const std::string& name) {
  const char* expected = "a list of grid names (str)";
  if (PyUnicode_Check(v.ptr())) return {v.cast<std::string>()};
  if (!PyList_Check(v.ptr()) && !PyTuple_Check(v.ptr())) fail(name, expected, v);
  std::vector<std::string> out;
  for (const py::handle item : v) {
    if (!PyUnicode_Check(item.ptr()))
      throw InvalidInput("'" + name + "' must be " + expected + ", but item " + std::to_string(out.size()) + " is " +
                         given(item));
    out.push_back(item.cast<std::string>());
  }
  return out;
}

py::array array_arg(const py::handle& v, const std::string& name, const std::string& expected) {
  if (py::isinstance<py::array>(v)) return py::reinterpret_borrow<py::array>(v);
  const std::string what = expected + " (a NumPy array or a nested list of numbers)";
  if (v.is_none() || PyUnicode_Check(v.ptr()) || PyBytes_Check(v.ptr()) || PyDict_Check(v.ptr()))
    fail(name, what, v);
  // NumPy converts sequences of numbers; ragged or non-numeric ones fail
  // (ensure returns null) or give object / string dtypes: refused alike.
  py::array a = py::array::ensure(v);
  if (!a) fail(name, what, v);
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw InvalidInput("'" + name + "' must be " + what + ", got a " + type_name(v) +
                       " that is not a rectangular array of numbers");
  return a;
}

ExecContext* context_arg(const py::handle& v, const std::string& name) {
  if (v.is_none()) return nullptr;
  if (py::isinstance<ExecContext>(v)) return v.cast<ExecContext*>();
  fail(name, "an exsynth._native.ExecContext or None", v);
}

py::dict dict_arg(const py::handle& v, const std::string& name, const std::string& expected) {
  if (!PyDict_Check(v.ptr())) fail(name, expected, v);
  return py::reinterpret_borrow<py::dict>(v);
}

void reject_unknown(const py::kwargs& extra, const std::string& options) {
  for (const auto item : extra)
    throw InvalidInput("unknown option '" + py::str(item.first).cast<std::string>() + "'; options: " + options);
}

}  // namespace exsynth::py_bind
