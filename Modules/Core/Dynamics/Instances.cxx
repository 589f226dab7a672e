// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Instances.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace ictk::dyn
{

namespace
{

std::vector<std::string> derive(const std::vector<std::string>& base,
  const std::vector<std::string>& removed, const std::vector<std::string>& added,
  const std::string& what, const std::string& instance, std::vector<std::string>* warnings)
{
  std::vector<std::string> out;
  for (const std::string& r : removed)
    if (std::find(base.begin(), base.end(), r) == base.end() && warnings)
      warnings->push_back(
        "instance '" + instance + "' removes the " + what + " '" + r + "' its template lacks");
  for (const std::string& b : base)
    if (std::find(removed.begin(), removed.end(), b) == removed.end())
      out.push_back(b);
  for (const std::string& a : added)
    if (std::find(out.begin(), out.end(), a) == out.end())
      out.push_back(a);
  return out;
}

std::string timeString(double t)
{
  std::ostringstream s;
  s.precision(17);
  s << t;
  return s.str();
}

} // namespace

void InstanceSet::addTemplate(IcTemplate t)
{
  for (const IcTemplate& e : templates_)
    if (e.name == t.name)
      throw std::invalid_argument("template '" + t.name + "' is defined twice");
  templates_.push_back(std::move(t));
}

std::size_t InstanceSet::addInstance(IcInstance i)
{
  for (const IcInstance& e : instances_)
    if (e.name == i.name)
      throw std::invalid_argument("instance '" + i.name + "' is defined twice");
  if (!i.templateName.empty() && !templateOf(i))
    throw std::invalid_argument(
      "instance '" + i.name + "' uses the unknown template '" + i.templateName + "'");
  instances_.push_back(std::move(i));
  return instances_.size() - 1;
}

const IcTemplate* InstanceSet::templateOf(const IcInstance& i) const
{
  for (const IcTemplate& t : templates_)
    if (t.name == i.templateName)
      return &t;
  return nullptr;
}

std::size_t InstanceSet::index(const std::string& name) const
{
  for (std::size_t i = 0; i < instances_.size(); ++i)
    if (instances_[i].name == name)
      return i;
  throw std::out_of_range("unknown instance '" + name + "'");
}

std::vector<std::string> InstanceSet::cells(std::size_t i, std::vector<std::string>* warnings) const
{
  const IcInstance& in = instances_.at(i);
  const IcTemplate* t = templateOf(in);
  return derive(t ? t->cells : std::vector<std::string>{}, in.removeCells, in.addCells, "cell",
    in.name, warnings);
}

std::vector<std::string> InstanceSet::relations(
  std::size_t i, std::vector<std::string>* warnings) const
{
  const IcInstance& in = instances_.at(i);
  const IcTemplate* t = templateOf(in);
  return derive(t ? t->relations : std::vector<std::string>{}, in.removeRelations, in.addRelations,
    "relation", in.name, warnings);
}

bool InstanceSet::isValid(std::size_t i, double t) const
{
  const IcInstance& in = instances_.at(i);
  return in.life.contains(t) && (!in.predicate || in.predicate(t));
}

std::vector<std::size_t> InstanceSet::validAt(double t) const
{
  std::vector<std::size_t> v;
  for (std::size_t i = 0; i < instances_.size(); ++i)
    if (isValid(i, t))
      v.push_back(i);
  return v;
}

std::size_t InstanceSet::activeAt(double t) const
{
  const std::vector<std::size_t> v = validAt(t);
  if (v.size() == 1)
    return v.front();
  std::vector<std::string> names;
  for (std::size_t i : v)
    names.push_back(instances_[i].name);
  std::string msg = v.empty() ? "no IC instance is valid at t = " + timeString(t)
                              : "several IC instances are valid at t = " + timeString(t) + ":";
  for (const std::string& n : names)
    msg += " " + n;
  throw InstanceError(msg, t, names);
}

std::vector<Transition> InstanceSet::trace(double t0, double t1, double dt,
  const std::vector<std::function<double(double)>>& guards,
  const frep::LocateOptions& options) const
{
  if (!(dt > 0.0) || !(t1 >= t0))
    throw std::invalid_argument("InstanceSet::trace: need t1 >= t0 and dt > 0");
  std::vector<Transition> out;
  std::size_t cur = activeAt(t0);
  out.push_back({ t0, "", instances_[cur].name });
  auto moveTo = [&](double t, std::size_t next)
  {
    if (next != cur)
    {
      out.push_back({ t, instances_[cur].name, instances_[next].name });
      cur = next;
    }
  };
  const auto steps = static_cast<long long>(std::ceil((t1 - t0) / dt - 1e-12));
  double a = t0;
  for (long long k = 1; k <= steps; ++k)
  {
    const double b = k == steps ? t1 : t0 + static_cast<double>(k) * dt;
    // Structural instants located on the guards, earliest first, repeatedly inside [a, b].
    double from = a;
    for (;;)
    {
      std::optional<frep::Crossing> first;
      for (const auto& g : guards)
      {
        auto c = frep::locateCrossing(g, from, b, options);
        if (c && (!first || c->time < first->time))
          first = c;
      }
      if (!first)
        break;
      moveTo(first->time, activeAt(first->time));
      // Resume just past the located instant: the refined root's residual may keep the old sign,
      // and must not be found again.
      from =
        first->time + std::max(64.0 * options.timeTolerance, 1e-12 * (1.0 + std::abs(first->time)));
      if (from >= b)
        break;
    }
    // Whatever holds after the last located instant; a change no guard explains is located by
    // bisection on the active instance's identity, once per change (an instance valid on a short
    // interval inside the step gives two boundaries).
    const std::size_t atB = activeAt(b);
    for (int changes = 0; atB != cur; ++changes)
    {
      double lo = from, hi = b;
      while (hi - lo > options.timeTolerance)
      {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
          break;
        if (activeAt(mid) == cur)
          lo = mid;
        else
          hi = mid;
      }
      if (hi >= b || changes >= options.maxIterations)
      {
        moveTo(b, atB);
        break;
      }
      moveTo(hi, activeAt(hi));
      from = hi;
    }
    a = b;
  }
  return out;
}

} // namespace ictk::dyn
