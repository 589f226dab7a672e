// SPDX-License-Identifier: BSD-3-Clause
#include "Mesh/Calculix.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace ictk::mesh
{

namespace
{

namespace fs = std::filesystem;

std::string number(double v)
{
  char s[40];
  std::snprintf(s, sizeof s, "%.12e", v);
  return s;
}

/// A *NSET of 1-based ids, 16 per line (ccx's limit for set lines).
void nodeSet(std::ostringstream& out, const char* name, const std::vector<std::size_t>& ids)
{
  out << "*NSET, NSET=" << name << "\n";
  for (std::size_t i = 0; i < ids.size(); ++i)
  {
    out << ids[i] << (i + 1 == ids.size() || (i + 1) % 16 == 0 ? "\n" : ", ");
  }
}

/// The executable `name` (a path, or looked up on PATH); empty when there is none.
std::string findExecutable(const std::string& name)
{
  if (name.empty())
  {
    return {};
  }
  if (name.find('/') != std::string::npos)
  {
    return ::access(name.c_str(), X_OK) == 0 ? name : std::string();
  }
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
  {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0)
    {
      return candidate.string();
    }
  }
  return {};
}

std::string slurp(const fs::path& p)
{
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The last `count` lines of a text, indented, for an error message.
std::string lastLines(const std::string& text, std::size_t count)
{
  std::deque<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
  {
    if (line.find_first_not_of(" \t\r_") == std::string::npos)
    {
      continue; // ccx frames its messages in blank and underscore lines
    }
    lines.push_back(line);
    if (lines.size() > count)
    {
      lines.pop_front();
    }
  }
  std::string out;
  for (const auto& l : lines)
  {
    out += "\n  | " + l;
  }
  return out.empty() ? "\n  | (empty)" : out;
}

} // namespace

std::array<double, 2> voigtReuss(const std::vector<DeckMaterial>& materials)
{
  double volume = 0, stiffness = 0, compliance = 0;
  for (const auto& m : materials)
  {
    volume += m.volume;
    stiffness += m.youngsModulus * m.volume;
    compliance += m.volume / m.youngsModulus;
  }
  return { stiffness / volume, volume / compliance };
}

CompressionCase compressionCase(
  const TetMesh& mesh, const CompressionOptions& options, std::string* appendix)
{
  if (!(options.displacement > 0) || !std::isfinite(options.displacement))
  {
    throw std::invalid_argument("compression: the platen displacement must be positive, not " +
      std::to_string(options.displacement));
  }
  if (mesh.points.empty())
  {
    throw std::invalid_argument("compression: the mesh has no points");
  }
  CompressionCase c;
  c.displacement = options.displacement;
  c.zMin = std::numeric_limits<double>::infinity();
  c.zMax = -c.zMin;
  for (const auto& p : mesh.points)
  {
    c.zMin = std::min(c.zMin, p[2]);
    c.zMax = std::max(c.zMax, p[2]);
  }
  c.height = c.zMax - c.zMin;
  if (!(c.height > 0))
  {
    throw std::invalid_argument("compression: the mesh has no height along z");
  }
  const double tolerance = options.tolerance > 0 ? options.tolerance : 1e-6 * c.height;
  for (std::size_t i = 0; i < mesh.points.size(); ++i)
  {
    if (mesh.points[i][2] <= c.zMin + tolerance)
    {
      c.bottomNodes.push_back(i + 1);
    }
    else if (mesh.points[i][2] >= c.zMax - tolerance)
    {
      c.topNodes.push_back(i + 1);
    }
  }
  if (c.bottomNodes.size() < 3 || c.topNodes.size() < 3)
  {
    throw std::invalid_argument("compression: a platen touches fewer than 3 nodes (" +
      std::to_string(c.bottomNodes.size()) + " at z = " + number(c.zMin) + ", " +
      std::to_string(c.topNodes.size()) + " at z = " + number(c.zMax) +
      "): the specimen needs flat faces on its z_min and z_max planes");
  }
  // The anchor nearest the bottom face's centre, the roller farthest from it in x.
  double lo[2] = { std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::infinity() };
  double hi[2] = { -lo[0], -lo[1] };
  for (auto id : c.bottomNodes)
  {
    for (int a = 0; a < 2; ++a)
    {
      lo[a] = std::min(lo[a], mesh.points[id - 1][std::size_t(a)]);
      hi[a] = std::max(hi[a], mesh.points[id - 1][std::size_t(a)]);
    }
  }
  const double centre[2] = { (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2 };
  double best = std::numeric_limits<double>::infinity();
  for (auto id : c.bottomNodes)
  {
    const auto& p = mesh.points[id - 1];
    const double d = std::hypot(p[0] - centre[0], p[1] - centre[1]);
    if (d < best)
    {
      best = d;
      c.anchorNode = id;
    }
  }
  const auto& anchor = mesh.points[c.anchorNode - 1];
  double farthest = 0;
  for (auto id : c.bottomNodes)
  {
    const double d =
      std::hypot(mesh.points[id - 1][0] - anchor[0], mesh.points[id - 1][1] - anchor[1]);
    if (d > farthest)
    {
      farthest = d;
      c.rollerNode = id;
    }
  }
  if (c.rollerNode == 0)
  {
    throw std::invalid_argument("compression: the bottom platen's nodes are all at one point");
  }
  {
    const auto& roller = mesh.points[c.rollerNode - 1];
    const double dx = (roller[0] - anchor[0]) / farthest, dy = (roller[1] - anchor[1]) / farthest;
    // Exactly along an axis when the node is (a structured mesh's), so the deck says u_y = 0.
    c.rollerNormal = { std::abs(dy) < 1e-12 ? 0.0 : -dy, std::abs(dx) < 1e-12 ? 0.0 : dx };
  }
  c.materials = deckMaterials(mesh, options.modulusBinWidth);
  for (const auto& m : c.materials)
  {
    c.volume += m.volume;
  }
  c.area = c.volume / c.height;
  const auto bounds = voigtReuss(c.materials);
  c.voigtModulus = bounds[0];
  c.reussModulus = bounds[1];
  if (appendix)
  {
    const auto& n = c.rollerNormal;
    const std::string rollerText = n[0] == 0 ? "u_y = 0"
      : n[1] == 0                            ? "u_x = 0"
                  : "n . u = 0, n = (" + number(n[0]) + ", " + number(n[1]) + ")";
    std::ostringstream out;
    out << "** compression between frictionless platens: u_z = 0 on " << bottomPlatenSet
        << " (z = " << number(c.zMin) << "), u_z = -" << number(c.displacement) << " on "
        << topPlatenSet << " (z = " << number(c.zMax) << ");\n"
        << "** rigid motion in the platens' plane held by node " << c.anchorNode
        << " (u_x = u_y = 0) and node " << c.rollerNode << " (" << rollerText << ")\n";
    nodeSet(out, bottomPlatenSet, c.bottomNodes);
    nodeSet(out, topPlatenSet, c.topNodes);
    // The rigid-motion constraints belong to the model (ccx takes *EQUATION only there), the
    // platens to the step.
    out << "*BOUNDARY\n" << c.anchorNode << ", 1, 2, 0\n";
    if (n[0] == 0 || n[1] == 0)
    {
      out << c.rollerNode << (n[0] == 0 ? ", 2, 2, 0\n" : ", 1, 1, 0\n");
    }
    else
    {
      // The larger term first: ccx eliminates the first term's degree of freedom.
      const bool xFirst = std::abs(n[0]) >= std::abs(n[1]);
      out << "*EQUATION\n2\n"
          << c.rollerNode << ", " << (xFirst ? 1 : 2) << ", " << number(xFirst ? n[0] : n[1])
          << ", " << c.rollerNode << ", " << (xFirst ? 2 : 1) << ", "
          << number(xFirst ? n[1] : n[0]) << "\n";
    }
    out << "*STEP\n*STATIC\n*BOUNDARY\n"
        << bottomPlatenSet << ", 3, 3, 0\n"
        << topPlatenSet << ", 3, 3, " << number(-c.displacement) << "\n";
    out << "*NODE FILE\nU, RF\n*EL FILE\nS\n"
        << "*NODE PRINT, NSET=" << topPlatenSet << ", TOTALS=ONLY\nRF\n"
        << "*NODE PRINT, NSET=" << bottomPlatenSet << ", TOTALS=ONLY\nRF\n"
        << "*END STEP\n";
    *appendix = out.str();
  }
  return c;
}

CompressionCase writeCompressionDeck(
  const TetMesh& mesh, const std::string& path, const CompressionOptions& options)
{
  AbaqusOptions abaqus;
  abaqus.heading = options.heading;
  abaqus.modulusBinWidth = options.modulusBinWidth;
  CompressionCase c = compressionCase(mesh, options, &abaqus.appendix);
  writeAbaqus(mesh, path, abaqus);
  return c;
}

double apparentModulus(const CompressionCase& c, double force)
{
  return force * c.height / (c.area * c.displacement);
}

CalculixRun runCalculix(const std::string& deck, const CalculixOptions& options)
{
  const fs::path deckPath = fs::absolute(deck);
  if (deckPath.extension() != ".inp")
  {
    throw std::invalid_argument("CalculiX: '" + deck + "' is not a .inp file");
  }
  std::error_code ec;
  if (!fs::is_regular_file(deckPath, ec))
  {
    throw std::runtime_error("CalculiX: cannot read the deck '" + deck + "'");
  }
  if (options.threads < 1)
  {
    throw std::invalid_argument("CalculiX: threads must be at least 1");
  }
  const std::string executable = findExecutable(options.executable);
  if (executable.empty())
  {
    throw std::runtime_error("cannot solve '" + deck + "': the CalculiX solver '" +
      options.executable +
      "' was not found (install the Debian package calculix-ccx; Scripts/setup does)");
  }
  CalculixRun run;
  run.folder = deckPath.parent_path().string();
  run.job = deckPath.stem().string();
  const fs::path folder = deckPath.parent_path();
  run.log = (folder / (run.job + ".log")).string();
  run.frd = (folder / (run.job + ".frd")).string();
  run.dat = (folder / (run.job + ".dat")).string();
  for (const char* stale : { ".frd", ".dat", ".sta", ".cvg" })
  {
    fs::remove(folder / (run.job + stale), ec);
  }

  // Everything the child needs is made before fork: it only changes folder, redirects and execs.
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
  {
    const std::string s = *e;
    if (s.rfind("OMP_NUM_THREADS=", 0) != 0 && s.rfind("CCX_NPROC_EQUATION_SOLVER=", 0) != 0)
    {
      env.push_back(s);
    }
  }
  env.push_back("OMP_NUM_THREADS=" + std::to_string(options.threads));
  env.push_back("CCX_NPROC_EQUATION_SOLVER=" + std::to_string(options.threads));
  std::vector<char*> envp;
  for (auto& s : env)
  {
    envp.push_back(s.data());
  }
  envp.push_back(nullptr);
  std::string arg0 = executable, arg1 = "-i", arg2 = run.job;
  char* argv[] = { arg0.data(), arg1.data(), arg2.data(), nullptr };
  const int log = ::open(run.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0)
  {
    throw std::runtime_error(
      "cannot solve '" + deck + "': cannot write '" + run.log + "': " + std::strerror(errno));
  }
  const std::string dir = run.folder;
  ProgressScope progress(options.progress);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0)
  {
    const int error = errno;
    ::close(log);
    throw std::runtime_error("cannot start CalculiX for '" + deck + "': " + std::strerror(error));
  }
  if (pid == 0)
  {
    // A process group of its own: a terminal's Ctrl-C reaches the caller, which cancels through
    // its progress callback and stops ccx here, rather than ccx dying under it.
    ::setpgid(0, 0);
    if (::chdir(dir.c_str()) != 0 || ::dup2(log, 1) < 0 || ::dup2(log, 2) < 0)
    {
      ::_exit(126);
    }
    ::execve(executable.c_str(), argv, envp.data());
    ::_exit(127);
  }
  ::close(log);
  int status = 0;
  for (;;)
  {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid)
    {
      break;
    }
    if (done < 0 && errno != EINTR)
    {
      throw std::runtime_error(
        "CalculiX on '" + deck + "': lost its process: " + std::strerror(errno));
    }
    try
    {
      progress.report(0);
    }
    catch (const Cancelled&)
    {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, &status, 0);
      throw;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string text = slurp(run.log);
  std::string why;
  if (WIFSIGNALED(status))
  {
    why = "killed by signal " + std::to_string(WTERMSIG(status));
  }
  else if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
  {
    why = "'" + executable + "' could not be run";
  }
  else if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
  {
    why = "exit status " + std::to_string(WEXITSTATUS(status));
  }
  else if (text.find("*ERROR") != std::string::npos)
  {
    why = "its log reports an error";
  }
  else if (text.find("Job finished") == std::string::npos)
  {
    why = "it did not finish";
  }
  else if (!fs::is_regular_file(run.frd, ec))
  {
    why = "it wrote no " + run.job + ".frd";
  }
  if (!why.empty())
  {
    throw std::runtime_error("CalculiX failed on '" + deck + "' (" + why + "); the end of " +
      run.log + ":" + lastLines(text, 12));
  }
  progress.report(1);
  return run;
}

std::map<std::string, std::array<double, 3>> readDatTotalForces(const std::string& path)
{
  std::ifstream in(path);
  if (!in)
  {
    throw std::runtime_error("cannot read '" + path + "'");
  }
  std::map<std::string, std::array<double, 3>> totals;
  std::string line;
  std::size_t lineNumber = 0;
  const std::string title = "total force (fx,fy,fz) for set ";
  while (std::getline(in, line))
  {
    ++lineNumber;
    const auto at = line.find(title);
    if (at == std::string::npos)
    {
      continue;
    }
    std::istringstream rest(line.substr(at + title.size()));
    std::string set;
    rest >> set;
    const std::size_t titleLine = lineNumber;
    std::array<double, 3> f{};
    bool found = false;
    while (std::getline(in, line))
    {
      ++lineNumber;
      if (line.find_first_not_of(" \t\r") == std::string::npos)
      {
        continue;
      }
      std::istringstream values(line);
      found = static_cast<bool>(values >> f[0] >> f[1] >> f[2]);
      break;
    }
    if (!found)
    {
      throw std::runtime_error(path + ":" + std::to_string(titleLine) +
        ": the total force of set " + set + " is not three numbers");
    }
    totals[set] = f;
  }
  return totals;
}

CompressionResult solveCompression(const TetMesh& mesh, const std::string& folder,
  const CompressionOptions& options, const CalculixOptions& calculix, const std::string& job)
{
  std::error_code ec;
  const bool fresh = !fs::exists(folder, ec);
  fs::create_directories(folder, ec);
  if (ec)
  {
    throw std::runtime_error("cannot make the folder '" + folder + "': " + ec.message());
  }
  CompressionResult r;
  const std::string deck = (fs::path(folder) / (job + ".inp")).string();
  try
  {
    r.compression = writeCompressionDeck(mesh, deck, options);
  }
  catch (...)
  {
    // A mesh that makes no deck leaves no folder behind.
    if (fresh)
    {
      fs::remove_all(folder, ec);
    }
    throw;
  }
  r.run = runCalculix(deck, calculix);
  const auto totals = readDatTotalForces(r.run.dat);
  const auto top = totals.find(topPlatenSet), bottom = totals.find(bottomPlatenSet);
  if (top == totals.end() || bottom == totals.end())
  {
    throw std::runtime_error(
      "CalculiX on '" + deck + "': " + r.run.dat + " has no total force of the platens");
  }
  r.topForce = top->second;
  r.bottomForce = bottom->second;
  r.apparentModulus = apparentModulus(r.compression, -r.topForce[2]);
  return r;
}

} // namespace ictk::mesh
