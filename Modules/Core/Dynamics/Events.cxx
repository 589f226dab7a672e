// SPDX-License-Identifier: BSD-3-Clause
#include "Dynamics/Events.h"

#include <stdexcept>

namespace ictk::dyn
{

Event Event::at(std::string name, double t, double priority, std::map<std::string, double> params)
{
  Event e;
  e.name = std::move(name);
  e.span = TimeSpan::interval(t, kInfinity);
  e.priority = priority;
  e.parameters = std::move(params);
  return e;
}

bool EventQueue::Item::operator<(const Item& o) const
{
  const double ta = event.time(), tb = o.event.time();
  if (ta != tb)
    return ta < tb;
  if (event.priority != o.event.priority)
    return event.priority > o.event.priority;
  if (event.name != o.event.name)
    return event.name < o.event.name;
  return sequence < o.sequence;
}

void EventQueue::push(Event e)
{
  queue_.insert(Item{ std::move(e), next_++ });
}

const Event& EventQueue::top() const
{
  if (queue_.empty())
    throw std::logic_error("EventQueue::top on an empty queue");
  return queue_.begin()->event;
}

Event EventQueue::pop()
{
  Event e = top();
  queue_.erase(queue_.begin());
  return e;
}

std::vector<Event> EventQueue::popUntil(double t)
{
  std::vector<Event> out;
  while (!queue_.empty() && queue_.begin()->event.time() <= t)
    out.push_back(pop());
  return out;
}

} // namespace ictk::dyn
