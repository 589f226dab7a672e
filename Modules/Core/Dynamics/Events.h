// SPDX-License-Identifier: BSD-3-Clause
// Events (thesis §3.7 L1327-1333, Table 2 L4080-4084): E = { name U, parameters P_j, time span T,
// priority p }. Events occur "normally but not necessarily, in a non-decreasing order of time"
// and "events with higher priorities are handled before events with lower priorities" (L1333).
// The queue is ordered by (start of the time span ascending, priority descending, name
// ascending, insertion order ascending), so the processing order never depends on addresses,
// hashes or threads.
#pragma once

#include "Dynamics/Time.h"

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace ictk::dyn
{

/// Names of the predefined events (L1333, L1343, L2075).
namespace events
{
inline const std::string TimeChanged = "TIME_CHANGED";
inline const std::string Init = "INIT";
inline const std::string Terminate = "TERMINATE";
inline const std::string TimeRejected = "TIME_REJECTED";
} // namespace events

struct Event
{
  std::string name;
  std::map<std::string, double> parameters;
  /// When the event occurs. Unknown in advance: only the start is set ([t, +inf), L4082).
  TimeSpan span;
  double priority = 1.0;

  /// The start of the span (events with an empty span occur at -inf, i.e. immediately).
  double time() const { return span.empty() ? -kInfinity : span.start(); }
  static Event at(std::string name, double t, double priority = 1.0,
    std::map<std::string, double> parameters = {});
};

class EventQueue
{
public:
  void push(Event e);
  bool empty() const { return queue_.empty(); }
  std::size_t size() const { return queue_.size(); }
  const Event& top() const;
  Event pop();
  /// Removes and returns, in queue order, every event whose time is <= t.
  std::vector<Event> popUntil(double t);
  void clear() { queue_.clear(); }

private:
  struct Item
  {
    Event event;
    std::uint64_t sequence = 0;
    bool operator<(const Item& o) const;
  };
  std::set<Item> queue_;
  std::uint64_t next_ = 0;
};

} // namespace ictk::dyn
