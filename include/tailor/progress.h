// tailor: progress callbacks of the long-running calls (loading, mapping, export, tiling).
//
// The library never prints: a caller that wants a progress bar passes a callback and draws it
// (the CLI's bar: apps/tailor/cli.h). Callbacks are called now and then (every few MB of a file,
// every few thousand faces), never per element; returning false cancels the call, which then
// fails with kCancelled and leaves its output empty (files: nothing written).
#pragma once

#include <functional>
#include <string_view>

namespace tailor {

//! Progress in [0, 1]; return false to cancel.
using ProgressCallback = std::function<bool(float)>;

//! Progress of one stage of a pipeline: `stage` names it ("orientation", "mapping", "closing", "relaxing",
//! "metrics"), `done` is in [0, 1] of that stage; return false to cancel.
using StageProgressCallback = std::function<bool(std::string_view stage, float done)>;

}  // namespace tailor
