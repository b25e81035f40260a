// A long rocklab call made from Python: the work runs on its own thread with the GIL released,
// while the calling thread wakes every 0.1 s (holding the GIL only then) to hand the latest
// progress line to the caller's callback and to let Ctrl-C through. Ctrl-C (or an exception in
// the callback) sets the interrupt flag every rocklab command polls; the command stops the way
// `rocklab` stops on SIGINT (nothing half-written) and the Python exception is raised once the
// work has ended. Units: SI (the progress times are seconds).
#pragma once

#include "io/progress.hpp"

#include <pybind11/pybind11.h>

#include <omp.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

namespace rocklab::python {

namespace py = pybind11;

/// Run `work(interrupt)` as described above; `progress` is None or a callable taking (tag,
/// message, fraction, elapsed_s, eta_s) with fraction and eta_s None when unknown; `threads` > 0
/// sets the OpenMP threads of the work (0: OMP_NUM_THREADS or every core).
template <class R>
R released_call(const py::object& progress, int threads,
                const std::function<R(const std::atomic<bool>*)>& work) {
  std::atomic<bool> stop{false};
  std::mutex mu;
  std::condition_variable cv;
  bool done = false;
  std::optional<ProgressEvent> latest;
  std::optional<R> out;
  std::exception_ptr err;
  std::optional<py::error_already_set> py_err;
  const bool want_progress = !progress.is_none();
  {
    py::gil_scoped_release nogil;
    std::thread worker([&] {
      if (threads > 0)
        omp_set_num_threads(threads);
      std::optional<ProgressSink> sink;
      if (want_progress)
        sink.emplace([&](const ProgressEvent& e) {
          const std::lock_guard<std::mutex> lock(mu);
          latest = e;
        });
      try {
        out.emplace(work(&stop));
      } catch (...) {
        err = std::current_exception();
      }
      {
        const std::lock_guard<std::mutex> lock(mu);
        done = true;
      }
      cv.notify_all();
    });
    for (bool finished = false; !finished;) {
      std::optional<ProgressEvent> event;
      {
        std::unique_lock<std::mutex> lock(mu);
        cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; });
        finished = done;
        event.swap(latest);
      }
      if (py_err)
        continue; // stopping: wait for the work to end
      const py::gil_scoped_acquire gil;
      try {
        if (PyErr_CheckSignals() != 0) // Ctrl-C: the default handler raised KeyboardInterrupt
          throw py::error_already_set();
        if (event && want_progress)
          progress(event->tag, event->what,
                   event->fraction >= 0 ? py::object(py::float_(event->fraction)) : py::none(),
                   event->elapsed_s,
                   event->eta_s >= 0 ? py::object(py::float_(event->eta_s)) : py::none());
      } catch (py::error_already_set& e) {
        py_err.emplace(std::move(e));
        stop.store(true);
      }
    }
    worker.join();
  }
  if (py_err)
    throw *py_err;
  if (err)
    std::rethrow_exception(err);
  return std::move(*out);
}

} // namespace rocklab::python
