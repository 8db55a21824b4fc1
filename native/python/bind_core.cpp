// Errors and ExecContext: the pieces every binding area shares.
#include <pybind11/pybind11.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "exsynth/errors.hpp"
#include "exsynth/exec_context.hpp"
#include "exsynth/memory_budget.hpp"
#include "arguments.hpp"

namespace py = pybind11;

namespace exsynth::py_bind {
namespace {

// Created once at import; live as long as the interpreter.
PyObject* g_error = nullptr;
PyObject* g_invalid = nullptr;
PyObject* g_budget = nullptr;
PyObject* g_cancelled = nullptr;
PyObject* g_io = nullptr;

PyObject* new_exception(py::module_& m, const char* name, py::handle bases, const char* doc) {
  const std::string qualified = std::string("exsynth._native.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (!cls) throw py::error_already_set();
  m.add_object(name, py::handle(cls));  // add_object steals nothing: keep our reference
  return cls;
}

}  // namespace

void bind_core(py::module_& m) {
  g_error = new_exception(m, "Error", PyExc_RuntimeError, "Base class of every exsynth engine error.");
  g_invalid = new_exception(m, "InvalidInputError", py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)),
                            "An argument is malformed; the message names it and says what to change.");
  g_budget = new_exception(m, "OverBudgetError", py::make_tuple(py::handle(g_error), py::handle(PyExc_MemoryError)),
                           "The job would need more memory than its budget (checked before allocating).");
  g_cancelled = new_exception(m, "CancelledError", py::handle(g_error), "The job was cancelled through its ExecContext.");
  g_io = new_exception(m, "IoError", py::make_tuple(py::handle(g_error), py::handle(PyExc_OSError)),
                       "A file cannot be read or written; the message names it and says why.");

  // One C++ class -> one Python class; nothing is swallowed.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidInput& e) {
      PyErr_SetString(g_invalid, e.what());
    } catch (const OverBudget& e) {
      PyErr_SetString(g_budget, e.what());
    } catch (const Cancelled& e) {
      PyErr_SetString(g_cancelled, e.what());
    } catch (const IoError& e) {
      PyErr_SetString(g_io, e.what());
    } catch (const Error& e) {
      PyErr_SetString(g_error, e.what());
    }
  });

  py::class_<ExecContext>(m, "ExecContext",
                          "Progress (0..1), stage name and cancel flag of a running job; thread-safe.\n"
                          "Pass it as ctx= to a long call running on a worker thread, read progress\n"
                          "and stage from the UI thread, call cancel() to stop the job.")
      .def(py::init<>())
      .def("cancel", &ExecContext::cancel, "Ask the running job to stop; it raises CancelledError.")
      .def_property_readonly("cancelled", &ExecContext::cancelled)
      .def_property_readonly("progress", &ExecContext::progress)
      .def_property_readonly("stage", &ExecContext::stage)
      .def(
          "set_span",
          [](ExecContext& c, const RealArg& lo, const RealArg& hi) {
            const double l = real_arg(lo, "lo", 0.0, 1.0), h = real_arg(hi, "hi", 0.0, 1.0);
            if (l > h)
              throw InvalidInput("'lo' must not exceed 'hi' (the share [lo, hi] of the progress bar), got lo=" +
                                 short_repr(lo) + ", hi=" + short_repr(hi));
            c.set_span(l, h);
          },
          py::arg("lo"), py::arg("hi"),
           "Give the next call the share [lo, hi] of the progress bar: its own 0..1 then reads lo..hi.")
      .def("__repr__", [](const ExecContext& c) {
        return "<ExecContext stage='" + c.stage() + "' progress=" + std::to_string(c.progress()) +
               (c.cancelled() ? " cancelled>" : ">");
      });

  m.def(
      "with_threads",
      [](const IntArg& threads, const py::object& fn) {
        const int n = int_arg(threads, "threads", 1, 256);
        if (!PyCallable_Check(fn.ptr())) throw InvalidInput("'fn' must be callable, got " + short_repr(fn));
        // An arena of n slots under a cap of n runs the engine's parallel
        // loops started from fn on exactly n threads, even beyond the cores.
        tbb::global_control cap(tbb::global_control::max_allowed_parallelism, std::size_t(n));
        tbb::task_arena arena(n);
        return arena.execute([&] { return fn(); });
      },
      py::arg("threads"), py::arg("fn"),
      "Call fn() with the engine's parallel work on exactly `threads` threads (1..256; more than the\n"
      "machine's cores is allowed): e.g. 1 to leave the other cores free. Results do not depend on it.");

  m.attr("DEFAULT_MEMORY_BUDGET") = py::int_(kDefaultMemoryBudget);
}

}  // namespace exsynth::py_bind
