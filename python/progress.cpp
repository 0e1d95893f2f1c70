// The progress bridge: the library's callbacks, called with the GIL released, reach Python only
// every 50 ms, so a long map costs a few hundred GIL round trips whatever its size.
#include "bindings.h"

namespace tailor::python {

std::function<bool(double)> ProgressBridge::function() {
  return [this](double fraction) { return report(fraction); };
}

bool ProgressBridge::report(double fraction) {
  const std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return true;  // another thread is reporting right now
  if (error_ || stopped_by_callback_) return false;
  const auto now = std::chrono::steady_clock::now();
  if (fraction < 1.0 && now - last_ < std::chrono::milliseconds(50)) return true;
  last_ = now;
  const py::gil_scoped_acquire gil;
  try {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C: KeyboardInterrupt
    // The end once: the last stages each report 1.0. Other repeats go through (throttled above):
    // a retry or the closing's tail repeats its fraction, and the callback may cancel there.
    if (!callback_.is_none() && !(fraction >= 1.0 && last_fraction_ >= 1.0)) {
      last_fraction_ = fraction;
      const py::object answer = callback_(fraction);
      // False stops, and any other false value but None (numpy's False from `f < 0.5`, 0); a
      // truth test that raises propagates.
      const int truth = answer.is_none() ? 1 : PyObject_IsTrue(answer.ptr());
      if (truth < 0) throw py::error_already_set();
      if (truth == 0) {
        stopped_by_callback_ = true;
        return false;
      }
    }
  } catch (py::error_already_set& e) {
    error_.emplace(std::move(e));
    return false;
  }
  return true;
}

void ProgressBridge::finish(const Status& status) {
  if (error_) {
    error_->restore();
    error_.reset();
    throw py::error_already_set();
  }
  if (!status) raise_status(status);
  if (!callback_.is_none() && last_fraction_ < 1.0) callback_(1.0);
}

}  // namespace tailor::python
