// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Progress and cancellation, the same for every long operation of the core (sampling, meshing,
// discretisation, tetrahedralisation, a dynamic model's run): OpenVDB's one-interrupter idea as a
// callback. The operation calls progress(fraction) with fraction in [0, 1] from the thread that
// called it; a false answer asks it to stop, and it then throws Cancelled, leaving what the caller
// passed in unchanged. The VTK layer maps it to UpdateProgress/AbortExecute
// (Modules/VTK/Common/ictkRequest.h); the CLI to its progress display and Ctrl-C.

#include <functional>
#include <stdexcept>
#include <string>

namespace ictk
{

/// The progress callback of every option struct; empty: no reports, no cancellation.
using Progress = std::function<bool(double)>;

/// Thrown by an operation whose progress callback asked it to stop.
class Cancelled : public std::runtime_error
{
public:
  explicit Cancelled(const std::string& what = "cancelled")
    : std::runtime_error(what)
  {
  }
};

namespace frep
{
// The kernel's historical names, the same types.
using ictk::Cancelled;
using ictk::Progress;
} // namespace frep

} // namespace ictk
