// `oobleck sweep SCENE --vary KEY=SPEC ... --out DIR`: a grid of `oobleck run`s (issue 42, item 5).
// Every combination of the varied values (the Cartesian product, the last --vary fastest) is one
// child process of this executable, `oobleck run SCENE --set KEY=VALUE ... --out DIR/<run>`, at
// most --jobs at a time, its stdout and stderr in DIR/<run>/log.txt. A run whose folder holds a
// complete summary.json is skipped, one with a checkpoint but no complete summary continues with
// `oobleck run --restart`, any other starts afresh; so a sweep that was stopped (Ctrl-C, SIGTERM:
// forwarded to the runs, which leave checkpoints) or that had failures resumes where it was.
// DIR/sweep.csv (written atomically) holds one row per run: the varied values, the run's folder,
// every scalar of its summary.json under its dotted key, status and message. Exit status: 0 if
// every run succeeded, 3 if any failed, 2 on bad input (before anything is written), 128 + N
// after signal N.
#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "oobleck/core/comm.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/run/stop.hpp"
#include "oobleck/scene/config.hpp"
#include "oobleck/scene/key_list.hpp"

namespace oobleck::cli {
namespace {
namespace fs = std::filesystem;

constexpr int kMaxJobs = 1024;      // children tracked by the signal handler
constexpr long kMaxValues = 10000;  // values of one --vary range
constexpr std::size_t kMaxRuns = 100000;

// ---------------------------------------------------------------------------------------------
// --vary KEY=SPEC

struct Vary {
  std::string option;  ///< as given, for messages
  std::string key;     ///< as written before '=' (the column name)
  std::vector<std::string> values;
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

/// The whole of `s` as a finite double.
std::optional<double> parse_number(const std::string& s) {
  double v = 0.0;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (first != last && *first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last || first == last || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// Decimal places a number is written with ("0.46": 2, "1e-3": 3, "2.5e-4": 5, "5": 0).
int decimals(const std::string& s) {
  int frac = 0;
  long exponent = 0;
  const auto e = s.find_first_of("eE");
  const std::string mantissa = s.substr(0, e);
  if (const auto dot = mantissa.find('.'); dot != std::string::npos) frac = static_cast<int>(mantissa.size() - dot - 1);
  if (e != std::string::npos) exponent = std::strtol(s.c_str() + e + 1, nullptr, 10);
  return static_cast<int>(std::clamp<long>(frac - exponent, 0, 400));
}

/// start:stop:step, stop included within 1e-9 of a step. Each value is start + i*step rounded to
/// the decimals of start and step (0.46:0.50:0.01 gives 0.47, not 0.47000000000000003), written
/// in the shortest form that reads back to the same double.
std::vector<std::string> range_values(const std::string& option, const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  for (std::string p; std::getline(ss, p, ':');) parts.push_back(trim(p));
  if (parts.size() != 3 || spec.back() == ':')
    throw InputError(fmt::format("--vary {}: a range is start:stop:step (three numbers)", option));
  const char* names[3] = {"start", "stop", "step"};
  double v[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const auto x = parse_number(parts[k]);
    if (!x)
      throw InputError(fmt::format("--vary {}: range {} '{}' is not a finite number", option, names[k], parts[k]));
    v[k] = *x;
  }
  const double start = v[0], stop = v[1], step = v[2];
  if (!(step > 0.0)) throw InputError(fmt::format("--vary {}: step {} must be > 0", option, parts[2]));
  const double span = (stop - start) / step;
  if (span < -1e-9) throw InputError(fmt::format("--vary {}: stop {} is below start {}", option, parts[1], parts[0]));
  if (!(span < static_cast<double>(kMaxValues)))
    throw InputError(fmt::format("--vary {}: more than {} values", option, kMaxValues));
  const long n = static_cast<long>(std::floor(span + 1e-9)) + 1;
  const int d = std::max(decimals(parts[0]), decimals(parts[2]));
  std::vector<std::string> out;
  for (long i = 0; i < n; ++i) {
    const double raw = start + static_cast<double>(i) * step;
    const std::string rounded = fmt::format("{:.{}f}", raw, d);
    out.push_back(fmt::format("{}", parse_number(rounded).value_or(raw)));
  }
  return out;
}

Vary parse_vary(const std::string& option) {
  Vary v;
  v.option = option;
  const auto eq = option.find('=');
  if (eq == std::string::npos)
    throw InputError(fmt::format("--vary {}: expected KEY=SPEC (SPEC: a,b,c or start:stop:step)", option));
  v.key = trim(option.substr(0, eq));
  const std::string spec = trim(option.substr(eq + 1));
  if (v.key.empty()) throw InputError(fmt::format("--vary {}: the key is empty", option));
  if (spec.empty()) throw InputError(fmt::format("--vary {}: no values after '='", option));
  if (spec.find(',') == std::string::npos && spec.find(':') != std::string::npos) {
    v.values = range_values(option, spec);
  } else {
    std::stringstream ss(spec);
    int k = 0;
    for (std::string p; std::getline(ss, p, ',');) {
      ++k;
      if (trim(p).empty()) throw InputError(fmt::format("--vary {}: value {} is empty", option, k));
      v.values.push_back(trim(p));
    }
    if (spec.back() == ',') throw InputError(fmt::format("--vary {}: value {} is empty", option, k + 1));
  }
  std::set<std::string> seen;
  for (const auto& x : v.values)
    if (!seen.insert(x).second) throw InputError(fmt::format("--vary {}: value {} is given twice", option, x));
  return v;
}

/// A folder-name-safe copy: letters, digits and . - + _ kept, anything else '_'.
std::string sanitize(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '-' || c == '+' || c == '_';
    out += ok ? c : '_';
  }
  return out;
}

/// FNV-1a 64 of `s`, for names too long for a file system.
std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

// ---------------------------------------------------------------------------------------------
// the runs

enum class Start { Skip, Fresh, Restart };
enum class Status { Pending, Running, Ok, Failed, Stopped };

struct Run {
  std::vector<std::string> values;  ///< one per --vary
  std::string name, dir;
  Start start = Start::Fresh;
  Status status = Status::Pending;
  std::string message;
  double seconds = 0.0;
  pid_t pid = -1;
  int slot = -1;
  std::string log;
  std::int64_t log_offset = 0;  ///< where this attempt's output begins in log.txt
  std::chrono::steady_clock::time_point t0;
};

/// The run's summary.json, if it parses and says "complete": true.
std::optional<nlohmann::ordered_json> complete_summary(const std::string& dir) {
  std::ifstream in(dir + "/summary.json");
  if (!in) return std::nullopt;
  try {
    auto j = nlohmann::ordered_json::parse(in);
    if (j.is_object() && j.contains("complete") && j["complete"].is_boolean() && j["complete"].get<bool>()) return j;
  } catch (const nlohmann::json::exception&) {
  }
  return std::nullopt;
}

/// Every scalar (number, bool, string, null) of `j` at any depth of its objects, under dotted
/// keys; arrays are left out. Numbers in the shortest form that reads back exactly.
void flatten(const nlohmann::ordered_json& j, const std::string& key,
             std::vector<std::pair<std::string, std::string>>& out) {
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, key.empty() ? k : fmt::format("{}.{}", key, k), out);
  } else if (j.is_array() || key.empty()) {
    return;
  } else if (j.is_null()) {
    out.emplace_back(key, "");
  } else if (j.is_boolean()) {
    out.emplace_back(key, j.get<bool>() ? "true" : "false");
  } else if (j.is_number_unsigned()) {
    out.emplace_back(key, fmt::format("{}", j.get<std::uint64_t>()));
  } else if (j.is_number_integer()) {
    out.emplace_back(key, fmt::format("{}", j.get<std::int64_t>()));
  } else if (j.is_number_float()) {
    const double x = j.get<double>();
    out.emplace_back(key, std::isfinite(x) ? fmt::format("{}", x) : std::string());
  } else if (j.is_string()) {
    out.emplace_back(key, j.get<std::string>());
  }
}

/// The unit of a scene key or alias as the scene file's comment gives it ("# [m/s] ..."; "[-]"
/// is "1"), or "" when it gives none.
std::string scene_key_unit(const scene::SceneKeyList& keys, const std::string& key) {
  std::string comment, target = key;  // (an alias's comment, else its key's)
  for (const auto& a : keys.aliases)
    if (a.name == key || a.key == key) {
      comment = a.comment;
      target = a.key;
    }
  for (const auto& k : keys.keys)
    if (comment.empty() && k.key == target) comment = k.comment;
  const auto close = comment.find(']');
  if (comment.empty() || comment.front() != '[' || close == std::string::npos) return {};
  std::string unit = trim(comment.substr(1, close - 1));
  if (unit == "-") unit = "1";
  return unit.find_first_of(",=") == std::string::npos ? unit : std::string();
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' '))) return s;
  std::string out = "\"";
  for (char c : s) out += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// The last non-empty line of `path` from byte `offset` on (a progress bar's last redraw).
std::string last_line(const std::string& path, std::int64_t offset) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  in.seekg(0, std::ios::end);
  const std::int64_t size = in.tellg();
  const std::int64_t from = std::max(offset, size - 65536);
  if (size <= from) return "";
  in.seekg(from);
  std::string text(static_cast<std::size_t>(size - from), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  std::string line;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);) {
    if (const auto cr = l.find_last_of('\r'); cr != std::string::npos) l = l.substr(cr + 1);
    if (!trim(l).empty()) line = trim(l);
  }
  return line;
}

std::string signal_name(int s) {
  switch (s) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGKILL: return "SIGKILL";
    case SIGSEGV: return "SIGSEGV";
    case SIGABRT: return "SIGABRT";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGXFSZ: return "SIGXFSZ";
    default: return fmt::format("signal {}", s);
  }
}

std::string self_exe() {
  std::error_code ec;
  const auto p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError(fmt::format("sweep: cannot find this executable (/proc/self/exe: {})", ec.message()));
  return p.string();
}

// ---------------------------------------------------------------------------------------------
// signals: forwarded to the running children; no new run starts after one

std::atomic<int> g_signal{0};
std::array<std::atomic<pid_t>, kMaxJobs> g_children{};
static_assert(std::atomic<pid_t>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "a signal handler may only touch lock-free atomics");

extern "C" void on_sweep_signal(int signal) {
  g_signal.store(signal);
  for (auto& c : g_children) {
    const pid_t pid = c.load();
    if (pid > 0) ::kill(pid, signal);
  }
}

class ForwardSignals {
 public:
  ForwardSignals() {
    struct sigaction sa {};
    sa.sa_handler = on_sweep_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // waitpid returns EINTR: the loop sees the signal at once
    sigaction(SIGINT, &sa, &previous_int_);
    sigaction(SIGTERM, &sa, &previous_term_);
  }
  ~ForwardSignals() {
    sigaction(SIGINT, &previous_int_, nullptr);
    sigaction(SIGTERM, &previous_term_, nullptr);
  }
  ForwardSignals(const ForwardSignals&) = delete;
  ForwardSignals& operator=(const ForwardSignals&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

/// Blocks SIGINT and SIGTERM while alive (a child is started and registered as one step).
class BlockSignals {
 public:
  BlockSignals() {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(SIG_BLOCK, &set, &previous_);
  }
  ~BlockSignals() { sigprocmask(SIG_SETMASK, &previous_, nullptr); }
  BlockSignals(const BlockSignals&) = delete;
  BlockSignals& operator=(const BlockSignals&) = delete;
  const sigset_t& previous() const { return previous_; }

 private:
  sigset_t previous_{};
};

// ---------------------------------------------------------------------------------------------

struct Options {
  std::string scene, out, plot;
  std::vector<std::string> vary, sets;
  int jobs = 1;
  int threads = 0;
  bool threads_given = false;
};

class Sweep {
 public:
  explicit Sweep(const Options& o) : o_(o) {}
  int execute();

 private:
  void validate();
  void plan();
  void launch(Run& r, int slot);
  void finish(Run& r, int wait_status);
  void write_csv() const;
  void make_plot() const;
  std::vector<std::string> child_args(const Run& r) const;

  const Options& o_;
  std::vector<Vary> varies_;
  std::vector<Run> runs_;
  std::string exe_;
  int threads_ = 0;  ///< --threads passed to each run (0: none)
};

void Sweep::validate() {
  if (comm::size() > 1)
    throw InputError(
        "sweep: start it without mpirun (each run is a process of its own; --ranks-per-run is not "
        "implemented)");
  if (o_.jobs < 1) throw InputError(fmt::format("--jobs {}: must be >= 1", o_.jobs));
  if (o_.jobs > kMaxJobs) throw InputError(fmt::format("--jobs {}: at most {}", o_.jobs, kMaxJobs));
  if (o_.threads_given && o_.threads < 0) throw InputError(fmt::format("--threads {}: must be >= 0", o_.threads));
  if (o_.out.empty()) throw InputError("--out: the sweep folder is empty");
  if (o_.vary.empty())
    throw InputError("sweep: at least one --vary KEY=SPEC is required (SPEC: a,b,c or start:stop:step)");
  std::error_code ec;
  if (!fs::is_regular_file(o_.scene, ec)) throw InputError(fmt::format("scene {}: no such file", o_.scene));
  if (fs::exists(o_.out, ec) && !fs::is_directory(o_.out, ec))
    throw InputError(fmt::format("--out {}: a file of that name is in the way", o_.out));
  if (!o_.plot.empty() && sanitize(o_.plot).find_first_not_of('.') == std::string::npos)
    throw InputError(fmt::format("--plot '{}': not a column name", o_.plot));
  std::set<std::string> keys;
  for (const auto& spec : o_.vary) {
    varies_.push_back(parse_vary(spec));
    if (!keys.insert(varies_.back().key).second)
      throw InputError(fmt::format("--vary {}: key {} is varied twice", spec, varies_.back().key));
  }
  for (const auto& s : o_.sets) {
    const std::string key = trim(s.substr(0, s.find('=')));
    if (keys.count(key) != 0) throw InputError(fmt::format("--set {}: {} is also given with --vary", s, key));
  }
  for (const char* reserved : {"run", "status", "message"})
    if (keys.count(reserved) != 0)
      throw InputError(fmt::format("--vary {}=...: '{}' is a column of sweep.csv of its own", reserved, reserved));
  if (o_.threads_given) {
    threads_ = o_.threads;
  } else if (o_.jobs > 1) {  // share the cores between the runs (OpenMP spinning on shared cores is slow)
    threads_ = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / o_.jobs);
  }
  exe_ = self_exe();
}

void Sweep::plan() {
  std::size_t total = 1;
  for (const auto& v : varies_) {
    total *= v.values.size();
    if (total > kMaxRuns) throw InputError(fmt::format("--vary: more than {} runs", kMaxRuns));
  }
  std::set<std::string> names;
  std::vector<std::size_t> idx(varies_.size(), 0);
  for (std::size_t n = 0; n < total; ++n) {
    Run r;
    std::string name;
    for (std::size_t k = 0; k < varies_.size(); ++k) {
      r.values.push_back(varies_[k].values[idx[k]]);
      if (k > 0) name += '_';
      name += sanitize(varies_[k].key);
      name += '=';
      name += sanitize(r.values.back());
    }
    if (name.size() > 200) name = fmt::format("{}_{:016x}", name.substr(0, 180), fnv1a(name));
    if (!names.insert(name).second)
      throw InputError(
          fmt::format("--vary: two runs would share the folder {} (values that differ only in "
                      "characters unsafe in file names)",
                      name));
    r.name = name;
    r.dir = (fs::path(o_.out) / name).string();
    r.log = r.dir + "/log.txt";
    runs_.push_back(std::move(r));
    for (std::size_t k = varies_.size(); k-- > 0;) {  // the last --vary fastest
      if (++idx[k] < varies_[k].values.size()) break;
      idx[k] = 0;
    }
  }
  // The first run's scene, loaded and validated here: an unknown key or a bad common --set is
  // reported before any folder is made (the other runs' values are checked by their runs).
  std::vector<std::string> overrides = o_.sets;
  for (std::size_t k = 0; k < varies_.size(); ++k) overrides.push_back(varies_[k].key + "=" + runs_[0].values[k]);
  try {
    (void)scene::load_scene(o_.scene, overrides);
  } catch (const InputError& e) {
    throw InputError(fmt::format("sweep: the first run ({}): {}", runs_[0].name, e.what()));
  }
}

std::vector<std::string> Sweep::child_args(const Run& r) const {
  std::vector<std::string> a = {exe_, "run"};
  if (r.start == Start::Restart) {
    a.insert(a.end(), {"--restart", r.dir});
  } else {
    a.push_back(o_.scene);
    for (const auto& s : o_.sets) a.insert(a.end(), {"--set", s});
    for (std::size_t k = 0; k < varies_.size(); ++k) a.insert(a.end(), {"--set", varies_[k].key + "=" + r.values[k]});
    a.insert(a.end(), {"--out", r.dir});
  }
  if (threads_ > 0) a.insert(a.end(), {"--threads", std::to_string(threads_)});
  return a;
}

void Sweep::launch(Run& r, int slot) {
  std::error_code ec;
  fs::create_directories(r.dir, ec);
  if (ec || !fs::is_directory(r.dir)) {
    r.status = Status::Failed;
    r.message = fmt::format("cannot create the run folder {}: {}", r.dir, ec ? ec.message() : "a file is in the way");
    return;
  }
  const int fd = ::open(r.log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    r.status = Status::Failed;
    r.message = fmt::format("cannot open {}: {}", r.log, std::strerror(errno));
    return;
  }
  auto args = child_args(r);
  std::string header = "$ oobleck";
  for (std::size_t k = 1; k < args.size(); ++k) header += " " + args[k];
  header += "\n";
  [[maybe_unused]] const auto written = ::write(fd, header.data(), header.size());  // the log is best effort
  r.log_offset = ::lseek(fd, 0, SEEK_END);
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();
  r.t0 = std::chrono::steady_clock::now();
  const BlockSignals blocked;
  const pid_t pid = ::fork();
  if (pid == 0) {
    // The child: only async-signal-safe calls until exec. Its own process group (a Ctrl-C at the
    // terminal reaches the sweep only, which forwards it once), SIGTERM if the sweep dies.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(143);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    sigprocmask(SIG_SETMASK, &blocked.previous(), nullptr);
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, 0);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    ::execv(argv[0], argv.data());
    static const char msg[] = "oobleck sweep: cannot execute the run\n";
    if (::write(2, msg, sizeof msg - 1) < 0) ::_exit(127);
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::close(fd);
  if (pid < 0) {
    r.status = Status::Failed;
    r.message = fmt::format("cannot start the run: fork: {}", std::strerror(fork_errno));
    return;
  }
  ::setpgid(pid, pid);  // (either side may do it first)
  r.pid = pid;
  r.slot = slot;
  r.status = Status::Running;
  g_children[static_cast<std::size_t>(slot)].store(pid);
  // A signal that arrived while blocked is delivered when `blocked` ends and reaches this child.
}

void Sweep::finish(Run& r, int wait_status) {
  g_children[static_cast<std::size_t>(r.slot)].store(0);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - r.t0).count();
  const int stop = g_signal.load();
  const std::string last = last_line(r.log, r.log_offset);
  if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0) {
    if (complete_summary(r.dir)) {
      r.status = Status::Ok;
      r.message = r.start == Start::Restart ? "continued from its checkpoint" : "";
    } else {
      r.status = Status::Failed;
      r.message = "exit 0 but no complete summary.json";
    }
    return;
  }
  const bool by_signal = WIFSIGNALED(wait_status);
  const int code = by_signal ? WTERMSIG(wait_status) : WEXITSTATUS(wait_status);
  const std::string how = by_signal ? fmt::format("killed by {}", signal_name(code)) : fmt::format("exit {}", code);
  if (stop != 0 && ((by_signal && (code == SIGINT || code == SIGTERM)) || (!by_signal && code > 128))) {
    r.status = Status::Stopped;
    r.message = fmt::format("stopped by {} ({}){}", signal_name(stop), how, last.empty() ? "" : ": " + last);
    return;
  }
  r.status = Status::Failed;
  r.message = last.empty() ? how : fmt::format("{}: {}", how, last);
}

const char* status_name(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::Failed: return "failed";
    case Status::Stopped: return "stopped";
    case Status::Running: return "running";
    case Status::Pending: return "not started";
  }
  return "";
}

void Sweep::write_csv() const {
  std::vector<std::string> columns;
  std::map<std::string, std::size_t> index;
  std::set<std::string> reserved = {"run", "status", "message"};
  for (const auto& v : varies_) reserved.insert(v.key);
  std::vector<std::map<std::size_t, std::string>> cells(runs_.size());
  std::map<std::string, std::string> unit_of;  // column -> unit, from the summaries' "units"
  for (std::size_t i = 0; i < runs_.size(); ++i) {
    if (runs_[i].status != Status::Ok) continue;
    auto summary = complete_summary(runs_[i].dir);
    if (!summary) continue;
    if (const auto u = summary->find("units"); u != summary->end()) {
      if (u->is_object())
        for (const auto& [key, unit] : u->items())
          if (unit.is_string()) unit_of[reserved.count(key) != 0 ? "summary." + key : key] = unit.get<std::string>();
      summary->erase(u);  // (the units are the first line's, not columns)
    }
    std::vector<std::pair<std::string, std::string>> flat;
    flatten(*summary, "", flat);
    for (auto& [key, value] : flat) {
      const std::string name = reserved.count(key) != 0 ? "summary." + key : key;
      auto [it, added] = index.emplace(name, columns.size());
      if (added) columns.push_back(name);
      cells[i][it->second] = value;
    }
  }
  // "# units: KEY=UNIT, ..." for the varied keys whose unit the scene file's comments give, then
  // the summaries' columns whose unit their "units" give.
  const scene::SceneKeyList keys = scene::list_scene_keys(o_.scene);
  std::vector<std::string> units;
  for (const auto& v : varies_)
    if (const std::string u = scene_key_unit(keys, v.key); !u.empty()) units.push_back(fmt::format("{}={}", v.key, u));
  for (const auto& c : columns)
    if (const auto u = unit_of.find(c); u != unit_of.end() && u->second.find_first_of(",=\n") == std::string::npos)
      units.push_back(fmt::format("{}={}", c, u->second));
  io::OutputFile f(o_.out + "/sweep.csv", "--out");
  auto& out = f.stream();
  out << "# units:" << (units.empty() ? "" : " ") << fmt::format("{}", fmt::join(units, ", ")) << "\n";
  std::string line;
  for (const auto& v : varies_) line += csv_field(v.key) + ",";
  line += "run";
  for (const auto& c : columns) line += "," + csv_field(c);
  out << line << ",status,message\n";
  for (std::size_t i = 0; i < runs_.size(); ++i) {
    const Run& r = runs_[i];
    line.clear();
    for (const auto& v : r.values) line += csv_field(v) + ",";
    line += csv_field(r.name);
    for (std::size_t c = 0; c < columns.size(); ++c) {
      line += ",";
      if (auto it = cells[i].find(c); it != cells[i].end()) line += csv_field(it->second);
    }
    out << line << "," << status_name(r.status) << "," << csv_field(r.message) << "\n";
  }
  f.commit();
}

void Sweep::make_plot() const {
  const std::string csv = o_.out + "/sweep.csv";
  const std::string png = (fs::path(o_.out) / (sanitize(o_.plot) + ".png")).string();
  std::error_code ec;
  if (!fs::exists(python(), ec)) {
    fmt::print(stderr, "sweep: warning: no plot {}: {} not found (set OOBLECK_PYTHON to a Python with matplotlib)\n",
               png, python());
    return;
  }
  std::vector<std::string> args = {csv, o_.plot, "--x", varies_[0].key};
  if (varies_.size() > 1) args.insert(args.end(), {"--group", varies_[1].key});
  try {
    plot("plot_sweep.py", args, png);
    fmt::print(stderr, "sweep: plot {}\n", png);
  } catch (const std::exception& e) {
    fmt::print(stderr, "sweep: warning: no plot {}: {}\n", png, e.what());
  }
}

int Sweep::execute() {
  validate();
  plan();
  // From here on the sweep writes: its folder, the runs' folders, sweep.csv.
  std::error_code ec;
  fs::create_directories(o_.out, ec);
  if (ec || !fs::is_directory(o_.out))
    throw InputError(fmt::format("--out {}: cannot create the folder: {}", o_.out,
                                 ec ? ec.message() : "a file of that name is in the way"));
  io::check_writable(o_.out + "/sweep.csv", "--out");
  std::size_t skip = 0, restart = 0;
  for (auto& r : runs_) {
    if (complete_summary(r.dir)) {
      r.start = Start::Skip;
      ++skip;
    } else if (fs::exists(r.dir + "/checkpoint.h5", ec)) {
      r.start = Start::Restart;
      ++restart;
    }
  }
  const std::size_t n = runs_.size();
  fmt::print(stderr, "sweep: {} run(s) in {}: {} complete, {} to continue, {} new; {} at a time{}\n", n, o_.out, skip,
             restart, n - skip - restart, o_.jobs, threads_ > 0 ? fmt::format(", {} thread(s) each", threads_) : "");
  g_signal.store(0);
  for (auto& c : g_children) c.store(0);
  const auto t0 = std::chrono::steady_clock::now();
  {
    const ForwardSignals forward;
    std::vector<Run*> running(static_cast<std::size_t>(o_.jobs), nullptr);
    std::size_t next = 0;
    auto progress = [&](const Run& r, std::size_t k, const std::string& what) {
      fmt::print(stderr, "sweep: [{}/{}] {}: {}\n", k + 1, n, r.name, what);
    };
    while (true) {
      // Start runs while a slot is free and no stop was asked for.
      while (next < n && g_signal.load() == 0) {
        Run& r = runs_[next];
        if (r.start == Start::Skip) {
          r.status = Status::Ok;
          r.message = "skipped: complete summary.json";
          progress(r, next, "skipped (complete summary.json)");
          ++next;
          continue;
        }
        const auto free_slot = std::find(running.begin(), running.end(), nullptr);
        if (free_slot == running.end()) break;
        launch(r, static_cast<int>(free_slot - running.begin()));
        if (r.status == Status::Running) {
          *free_slot = &r;
          progress(r, next, r.start == Start::Restart ? "started (continues from its checkpoint)" : "started");
        } else {
          progress(r, next, fmt::format("failed: {}", r.message));
        }
        ++next;
      }
      if (std::none_of(running.begin(), running.end(), [](const Run* r) { return r != nullptr; })) break;
      int st = 0;
      const pid_t pid = ::waitpid(-1, &st, 0);
      if (pid < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error(fmt::format("sweep: waitpid: {}", std::strerror(errno)));
      }
      for (auto& slot : running) {
        if (slot == nullptr || slot->pid != pid) continue;
        Run& r = *slot;
        slot = nullptr;
        finish(r, st);
        const std::size_t k = static_cast<std::size_t>(&r - runs_.data());
        progress(r, k,
                 fmt::format("{} in {:.2f} s{}", status_name(r.status), r.seconds,
                             r.message.empty() ? "" : " (" + r.message + ")"));
      }
    }
  }
  write_csv();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto count = [&](Status s) {
    return std::count_if(runs_.begin(), runs_.end(), [s](const Run& r) { return r.status == s; });
  };
  const long failed = static_cast<long>(count(Status::Failed));
  if (const int sig = g_signal.load(); sig != 0) {
    throw run::Stopped(fmt::format("sweep stopped by {} after {:.1f} s: {} ok, {} failed, {} stopped, {} not started; "
                                   "{}/sweep.csv written; the same command resumes the sweep",
                                   signal_name(sig), wall, count(Status::Ok), failed, count(Status::Stopped),
                                   count(Status::Pending), o_.out),
                       sig);
  }
  if (!o_.plot.empty()) make_plot();
  fmt::print("sweep: {} run(s) in {:.1f} s: {} ok, {} failed; table in {}/sweep.csv\n", n, wall, n - failed, failed,
             o_.out);
  std::fflush(stdout);  // before the failure count on stderr, also where both go to one pipe
  if (failed > 0) {
    fmt::print(stderr,
               "oobleck: sweep: {} of {} run(s) failed (status and message in {}/sweep.csv, output in each "
               "run's log.txt)\n",
               failed, n, o_.out);
    return 3;
  }
  return 0;
}

}  // namespace

void add_sweep_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("sweep",
                                 "run a scene over a grid of parameter values (one `oobleck run` per combination, "
                                 "resumable) and tabulate their summaries in DIR/sweep.csv");
  auto o = std::make_shared<Options>();
  cmd->add_option("scene", o->scene, "scene file (TOML)")->required();
  cmd->add_option("--vary", o->vary,
                  "KEY=a,b,c or KEY=start:stop:step (stop included): a scene key or [aliases] name, as --set; "
                  "repeat for a grid (the last varies fastest)");
  cmd->add_option("--set", o->sets, "override a scene key in every run: key.path=value or an [aliases] name");
  cmd->add_option("--jobs", o->jobs, "runs at a time (default 1)");
  cmd->add_option("--out", o->out, "sweep folder: DIR/<run>/ per run, DIR/sweep.csv")->required();
  cmd->add_option("--plot", o->plot, "also write DIR/QUANTITY.png: a column of sweep.csv against the first --vary key");
  auto* threads = cmd->add_option("--threads", o->threads,
                                  "OpenMP threads per run (default: all cores with --jobs 1, else cores / jobs)");
  cmd->callback([o, threads] {
    o->threads_given = threads->count() > 0;
    Sweep sweep(*o);
    const int status = sweep.execute();
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace oobleck::cli
