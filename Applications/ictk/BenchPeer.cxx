// SPDX-License-Identifier: BSD-3-Clause
// The rounds and the report of `ictk bench --peer-libfive` (BenchPeer.h); the workloads
// themselves are set up in BenchCommand.cxx.
#include "BenchPeer.h"

#include "ProgressDisplay.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <sys/wait.h>
#include <unistd.h>

namespace ictk::cli
{

namespace
{

double LoadAverage()
{
  std::ifstream in("/proc/loadavg");
  double load = -1;
  in >> load;
  return load;
}

std::string ShellQuote(const std::string& s)
{
  std::string q = "'";
  for (const char c : s)
  {
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return q + "'";
}

/// Runs `command` (quoted words) and returns its standard output; throws naming the command
/// when it cannot start or does not exit with 0.
std::string RunCommand(const std::vector<std::string>& words)
{
  std::string command, shown;
  for (const std::string& w : words)
  {
    command += (command.empty() ? "" : " ") + ShellQuote(w);
    shown += (shown.empty() ? "" : " ") + w;
  }
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe)
  {
    throw std::runtime_error("--peer-libfive: cannot run '" + shown + "'");
  }
  std::string out;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
  {
    out.append(buffer, n);
  }
  const int status = pclose(pipe);
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
  {
    std::ostringstream s;
    s << "--peer-libfive: '" << shown << "' failed ("
      << (status != -1 && WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                            : std::string("killed or not run"))
      << ")";
    throw std::runtime_error(s.str());
  }
  return out;
}

std::string Milliseconds(double seconds)
{
  std::ostringstream s;
  s.setf(std::ios::fixed);
  const double ms = seconds * 1e3;
  s.precision(ms < 10 ? 2 : ms < 100 ? 1 : 0);
  s << ms << " ms";
  return s.str();
}

std::string Times(double ratio)
{
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(ratio < 10 ? 2 : 1);
  s << ratio << "x";
  return s.str();
}

std::string DetailText(const nlohmann::json& details)
{
  std::string text;
  for (auto it = details.begin(); it != details.end(); ++it)
  {
    std::ostringstream value;
    if (it.value().is_number_float())
    {
      value.precision(3); // the JSON output keeps every digit
      value << it.value().get<double>();
    }
    else
    {
      value << (it.value().is_string() ? it.value().get<std::string>() : it.value().dump());
    }
    text += (text.empty() ? "" : ", ") + it.key() + " " + value.str();
  }
  return text;
}

struct SideResult
{
  std::vector<PeerRound> rounds;
  double seconds() const
  {
    std::vector<double> s;
    for (const PeerRound& r : rounds)
    {
      s.push_back(r.seconds);
    }
    return Median(s);
  }
  double cpuSeconds() const
  {
    std::vector<double> s;
    for (const PeerRound& r : rounds)
    {
      s.push_back(r.cpuSeconds);
    }
    return Median(s);
  }
};

} // namespace

PeerSide InProcessSide(std::string tool, std::string label, int runs, std::function<void()> run,
  std::function<nlohmann::json()> details)
{
  PeerSide side;
  side.tool = std::move(tool);
  side.label = std::move(label);
  side.round = [runs, run = std::move(run), details = std::move(details)]
  {
    run(); // warm-up
    std::vector<double> wall, cpu;
    for (int i = 0; i < runs; ++i)
    {
      const double c0 = CpuSeconds();
      const auto t0 = std::chrono::steady_clock::now();
      run();
      wall.push_back(Seconds(t0));
      cpu.push_back(CpuSeconds() - c0);
    }
    PeerRound r;
    r.seconds = Median(wall);
    r.cpuSeconds = Median(cpu);
    if (details)
    {
      r.details = details();
    }
    return r;
  };
  return side;
}

PeerSide LibfiveSide(std::string label, std::string l5bench, std::vector<std::string> args)
{
  PeerSide side;
  side.tool = "libfive";
  side.label = std::move(label);
  args.insert(args.begin(), std::move(l5bench));
  side.round = [args]
  {
    const std::string out = RunCommand(args);
    std::istringstream lines(out);
    std::string line;
    PeerRound r;
    bool timed = false;
    while (std::getline(lines, line))
    {
      if (line.empty() || line[0] != '{')
      {
        continue;
      }
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded())
      {
        continue;
      }
      if (!timed && j.contains("seconds"))
      {
        r.seconds = j.at("seconds").get<double>();
        r.cpuSeconds = j.value("cpu_seconds", 0.0);
        timed = true;
        continue;
      }
      for (auto it = j.begin(); it != j.end(); ++it)
      {
        if (it.key() != "workload")
        {
          r.details[it.key()] = it.value();
        }
      }
    }
    if (!timed)
    {
      throw std::runtime_error("--peer-libfive: '" + args[0] + " " + args[1] +
        "' printed no JSON line with \"seconds\":\n" + out);
    }
    return r;
  };
  return side;
}

bool PeerHasCommand(const std::string& l5bench, const std::vector<std::string>& args)
{
  std::string command = ShellQuote(l5bench);
  for (const std::string& a : args)
  {
    command += " " + ShellQuote(a);
  }
  command += " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

void CheckPeerExecutable(const std::string& path)
{
  if (access(path.c_str(), X_OK) != 0)
  {
    throw std::invalid_argument("--peer-libfive: '" + path +
      "' is not an executable file (../shared/bench/peers/libfive/build builds l5bench and "
      "prints its path)");
  }
}

void RunPeerBench(
  const std::vector<PeerCase>& cases, int rounds, bool json, const std::string& peerPath)
{
  const double loadStart = LoadAverage();
  std::vector<std::vector<SideResult>> results(cases.size());
  for (std::size_t c = 0; c < cases.size(); ++c)
  {
    const PeerCase& pc = cases[c];
    results[c].resize(pc.sides.size());
    for (int round = 0; round < rounds; ++round)
    {
      // Alternating the order too: a side is not always the one that runs after the other.
      for (std::size_t k = 0; k < pc.sides.size(); ++k)
      {
        const std::size_t s = round % 2 == 0 ? k : pc.sides.size() - 1 - k;
        results[c][s].rounds.push_back(pc.sides[s].round());
      }
    }
    if (!json)
    {
      std::cerr << "ictk bench: " << pc.workload << " done (" << rounds << " rounds)\n";
    }
  }
  const double loadEnd = LoadAverage();

  nlohmann::json all = nlohmann::json::object();
  all["rounds"] = rounds;
  all["peer_libfive"] = peerPath;
  all["load_average_start"] = loadStart;
  all["load_average_end"] = loadEnd;
  all["cases"] = nlohmann::json::array();
  std::ostringstream sides, ratios;
  sides << "| workload | threads | tool | side | time | CPU | rounds | reports |\n"
           "|---|---|---|---|---|---|---|---|\n";
  ratios << "| workload | ICTK side | peer side | ratio | over the rounds | goal |\n"
            "|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < cases.size(); ++c)
  {
    const PeerCase& pc = cases[c];
    nlohmann::json jc;
    jc["workload"] = pc.workload;
    jc["description"] = pc.what;
    jc["threads"] = pc.threads;
    jc["sides"] = nlohmann::json::array();
    for (std::size_t s = 0; s < pc.sides.size(); ++s)
    {
      const SideResult& r = results[c][s];
      nlohmann::json js;
      js["tool"] = pc.sides[s].tool;
      js["label"] = pc.sides[s].label;
      js["seconds"] = r.seconds();
      js["cpu_seconds"] = r.cpuSeconds();
      std::vector<double> roundSeconds;
      for (const PeerRound& round : r.rounds)
      {
        roundSeconds.push_back(round.seconds);
      }
      js["round_seconds"] = roundSeconds;
      js["details"] = r.rounds.back().details;
      std::string goal;
      if (pc.sides[s].goalSeconds)
      {
        js["goal_seconds"] = *pc.sides[s].goalSeconds;
        js["goal_met"] = r.seconds() <= *pc.sides[s].goalSeconds;
      }
      jc["sides"].push_back(js);
      const auto [lo, hi] = std::minmax_element(roundSeconds.begin(), roundSeconds.end());
      sides << "| " << pc.workload << " | " << pc.threads << " | " << pc.sides[s].tool << " | "
            << pc.sides[s].label << " | " << Milliseconds(r.seconds()) << " | "
            << Milliseconds(r.cpuSeconds()) << " | " << Milliseconds(*lo) << " - "
            << Milliseconds(*hi) << " | " << DetailText(r.rounds.back().details);
      if (pc.sides[s].goalSeconds)
      {
        sides << (r.rounds.back().details.empty() ? "" : "; ")
              << "goal <= " << Milliseconds(*pc.sides[s].goalSeconds) << ": "
              << (r.seconds() <= *pc.sides[s].goalSeconds ? "**met**" : "missed");
      }
      sides << " |\n";
    }
    jc["ratios"] = nlohmann::json::array();
    for (const PeerRatio& ratio : pc.ratios)
    {
      const SideResult& ictk = results[c][ratio.ictk];
      const SideResult& peer = results[c][ratio.peer];
      const double value = peer.seconds() / ictk.seconds();
      std::vector<double> perRound;
      for (std::size_t round = 0; round < ictk.rounds.size(); ++round)
      {
        perRound.push_back(peer.rounds[round].seconds / ictk.rounds[round].seconds);
      }
      const auto [lo, hi] = std::minmax_element(perRound.begin(), perRound.end());
      nlohmann::json jr;
      jr["ictk"] = pc.sides[ratio.ictk].label;
      jr["peer"] = pc.sides[ratio.peer].tool + " " + pc.sides[ratio.peer].label;
      jr["ratio"] = value;
      jr["round_ratios"] = perRound;
      ratios << "| " << pc.workload << " | " << pc.sides[ratio.ictk].label << " | "
             << pc.sides[ratio.peer].tool << " " << pc.sides[ratio.peer].label << " | "
             << Times(value) << " | " << Times(*lo) << " - " << Times(*hi) << " | ";
      if (ratio.goal)
      {
        jr["goal_ratio"] = *ratio.goal;
        jr["goal_met"] = value >= *ratio.goal;
        ratios << ">= " << Times(*ratio.goal) << ": "
               << (value >= *ratio.goal ? "**met**" : "missed");
      }
      ratios << " |\n";
      jc["ratios"].push_back(jr);
    }
    all["cases"].push_back(jc);
  }
  if (json)
  {
    std::cout << all.dump(2) << "\n";
    return;
  }
  std::ostringstream head;
  head.setf(std::ios::fixed);
  head.precision(2);
  head << "Side by side: " << rounds << " alternating round" << (rounds == 1 ? "" : "s")
       << ", each side's time the median of its round medians; load average " << loadStart
       << " at the start, " << loadEnd << " at the end (nproc " << sysconf(_SC_NPROCESSORS_ONLN)
       << "); libfive: " << peerPath << "\n\n";
  std::cout << head.str() << sides.str() << "\n"
            << "Ratios (peer time / ICTK time; above 1: ICTK is faster):\n\n"
            << ratios.str() << std::flush;
}

} // namespace ictk::cli
