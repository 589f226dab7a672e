// SPDX-License-Identifier: BSD-3-Clause
#include "ProgressDisplay.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <ctime>
#include <iomanip>
#include <iostream>

namespace ictk::cli
{
namespace
{

std::atomic<bool> InterruptedFlag{ false };

extern "C" void OnInterrupt(int)
{
  InterruptedFlag = true;
}

} // namespace

ProgressBar::ProgressBar(std::string label, bool lines, bool enabled)
  : Label(std::move(label))
  , Terminal(isatty(STDERR_FILENO) != 0)
  , Lines(lines)
  , Enabled(enabled)
{
}

void ProgressBar::Show(double fraction, const std::string& suffix)
{
  if (!this->Enabled || this->Finished || (!this->Terminal && !this->Lines))
  {
    return;
  }
  const int percent = static_cast<int>(std::floor(std::clamp(fraction, 0.0, 1.0) * 100));
  if (percent == this->LastShown && suffix == this->LastSuffix)
  {
    return;
  }
  if (this->Terminal)
  {
    constexpr int Width = 40;
    const int filled = percent * Width / 100;
    std::cerr << "\r" << this->Label << " [" << std::string(filled, '#')
              << std::string(Width - filled, ' ') << "] " << std::setw(3) << percent << "%"
              << (suffix.empty() ? "" : " ") << suffix << std::flush;
    if (percent == 100)
    {
      std::cerr << "\n";
      this->Finished = true;
    }
  }
  else if (percent / 25 != this->LastShown / 25 || this->LastShown < 0)
  {
    std::cerr << this->Label << ": " << percent << "%\n";
    this->Finished = percent == 100;
  }
  this->LastShown = percent;
  this->LastSuffix = suffix;
}

void ProgressBar::End()
{
  if (this->Enabled && this->Terminal && !this->Finished && this->LastShown >= 0)
  {
    std::cerr << "\n";
  }
  this->Finished = true;
}

InterruptScope::InterruptScope()
{
  InterruptedFlag = false;
  this->PreviousInt = std::signal(SIGINT, OnInterrupt);
  this->PreviousTerm = std::signal(SIGTERM, OnInterrupt);
}

InterruptScope::~InterruptScope()
{
  std::signal(SIGINT, this->PreviousInt);
  std::signal(SIGTERM, this->PreviousTerm);
}

bool Interrupted()
{
  return InterruptedFlag;
}

double Seconds(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double CpuSeconds()
{
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double Median(std::vector<double> values)
{
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

} // namespace ictk::cli
