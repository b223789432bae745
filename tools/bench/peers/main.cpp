// graspsim_peers: the scale scenes (bench/scale_scenes.hpp) stepped in graspsim and in ODE,
// MuJoCo and Bullet (where their packages are), each engine as its defaults have it, timed per
// step, each judged by the same outcome: energy, drift, rest, thrown (tools/bench/README.md,
// "Peers"). graspsim's engine is one more World (graspsim.cpp); the peers know nothing of it.
//
// Each (engine, layout, n, rate) is run --repeats times, each time in a child process of its
// own (fork), so that a run's peak RSS growth is that scene's alone (a process that ran a
// scene before keeps its freed memory, so a later scene's growth would read low), and an
// engine that aborts, crashes or runs out of memory fails that row, not the program.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "peers.hpp"

namespace graspsim::bench::peers {
namespace {

constexpr double kChildGrowth = 8.0 * (1 << 30);   // B of address space a run may add: past it, it
                                                   // fails out of memory instead of crowding the machine

// The engines this build can run: graspsim always; the peers where their packages were found.
std::vector<std::string> available_engines() {
#if GRASPSIM_PEERS
  return {"graspsim", "ode", "mujoco", "bullet"};
#else
  return {"graspsim"};
#endif
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ",") + item;
  return out;
}

struct Options {
  std::vector<std::string> engines = available_engines();
  std::vector<scale::Layout> layouts{scale::Layout::kApart, scale::Layout::kIsland, scale::Layout::kTower,
                                     scale::Layout::kPyramid, scale::Layout::kPile};
  std::vector<int> n{16, 64, 144, 400, 1000};
  std::vector<int> rates{50, 500, 3000};   // Hz
  double gap = 0.0;                        // m
  double duration = 2.0;                   // s simulated
  int repeats = 3;
  std::string csv;
  bool sleep = false;
  bool verbose = false;
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// us of CPU time this thread has used: unlike the wall time, not counting the time the
// scheduler gave other processes (the step is timed on a shared machine).
double thread_cpu_us() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e6 * static_cast<double>(ts.tv_sec) + 1e-3 * static_cast<double>(ts.tv_nsec);
}

// ---- the child: one run --------------------------------------------------------------------

Record g_record;         // the run so far, sent as it is by fail_run
int g_pipe = -1;         // the child's end of the pipe to the parent
bool g_verbose = false;  // print each World's notes (set before the fork)

[[noreturn]] void send_record_and_exit(int code) {
  const char* p = reinterpret_cast<const char*>(&g_record);
  std::size_t left = sizeof g_record;
  while (left > 0) {
    const ssize_t put = write(g_pipe, p, left);
    if (put <= 0) break;
    p += put;
    left -= static_cast<std::size_t>(put);
  }
  _exit(code);
}

void set_failed(const std::string& why) {
  std::snprintf(g_record.failed, sizeof g_record.failed, "%s", why.c_str());
}

// kB from /proc/self/status ("VmRSS:", "VmHWM:"); -1 if absent.
double status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) return std::atof(line.c_str() + std::strlen(key));
  return -1.0;
}

// Peak RSS is reset to the current RSS (Linux's clear_refs, "5"), so that VmHWM afterwards is
// this scene's peak, not the parent's that the fork copied.
void reset_peak_rss() {
  std::ofstream("/proc/self/clear_refs") << "5";
}

// J: sum of 1/2 m v^2 + 1/2 w . J w + m g z, the cube's J isotropic (m s^2 / 6).
double energy(const std::vector<BoxState>& boxes) {
  double e = 0.0;
  const double j = scale::cube_inertia();
  for (const BoxState& b : boxes) {
    const double v2 = b.v[0] * b.v[0] + b.v[1] * b.v[1] + b.v[2] * b.v[2];
    const double w2 = b.w[0] * b.w[0] + b.w[1] * b.w[1] + b.w[2] * b.w[2];
    e += 0.5 * scale::kMass * v2 + 0.5 * j * w2 + scale::kMass * scale::kGravity * b.p[2];
  }
  return e;
}

bool finite(const std::vector<BoxState>& boxes) {
  for (const BoxState& b : boxes)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(b.p[k]) || !std::isfinite(b.v[k]) || !std::isfinite(b.w[k])) return false;
  return true;
}

std::unique_ptr<World> make_world(const std::string& engine, const Scene& scene) {
  if (engine == "graspsim") return make_graspsim_world(scene);
#if GRASPSIM_PEERS
  if (engine == "ode") return make_ode_world(scene);
  if (engine == "mujoco") return make_mujoco_world(scene);
  if (engine == "bullet") return make_bullet_world(scene);
#endif
  throw std::invalid_argument("unknown engine " + engine);
}

// The end state's distance from the start and speed, the largest over the boxes (m, m/s).
void end_outcome(const std::vector<BoxState>& start, const std::vector<BoxState>& end) {
  for (std::size_t i = 0; i < end.size(); ++i) {
    const double dx = end[i].p[0] - start[i].p[0], dy = end[i].p[1] - start[i].p[1], dz = end[i].p[2] - start[i].p[2];
    const double v2 = end[i].v[0] * end[i].v[0] + end[i].v[1] * end[i].v[1] + end[i].v[2] * end[i].v[2];
    g_record.drift_end = std::max(g_record.drift_end, std::sqrt(dx * dx + dy * dy + dz * dz));
    g_record.speed_end = std::max(g_record.speed_end, std::sqrt(v2));
  }
}

// Median, min and max of the steps' wall times (us).
void step_statistics(std::vector<double> us) {
  if (us.empty()) return;
  const auto [lo, hi] = std::minmax_element(us.begin(), us.end());
  g_record.us_min = *lo;
  g_record.us_max = *hi;
  const std::size_t half = us.size() / 2;
  std::nth_element(us.begin(), us.begin() + static_cast<std::ptrdiff_t>(half), us.end());
  double median = us[half];
  if (us.size() % 2 == 0) median = 0.5 * (median + *std::max_element(us.begin(), us.begin() + static_cast<std::ptrdiff_t>(half)));
  g_record.us_median = median;
}

// Builds the scene, steps it for `duration`, fills g_record; false if the engine ran out of
// room for its contacts (World::out_of_room), the run then cut short unless it is the `last` try. Only World::step is timed;
// the states are read after every step (energy, height, finiteness), as a user's loop reads poses.
bool run_once(const std::string& engine, const Scene& scene, double duration, bool last) {
  const int planned = std::max(1, static_cast<int>(std::llround(duration / scene.dt)));
  std::vector<double> us, cpu_us;   // us: wall and this thread's CPU time of each step
  us.reserve(static_cast<std::size_t>(planned));
  cpu_us.reserve(static_cast<std::size_t>(planned));
  std::vector<BoxState> start, now;
  start.reserve(scene.boxes.size());
  now.reserve(scene.boxes.size());
  g_record = Record{};
  g_record.room = scene.room;
  reset_peak_rss();
  const double rss_before = status_kb("VmRSS:");   // kB
  std::unique_ptr<World> world = make_world(engine, scene);
  world->read(start);
  g_record.energy_start = energy(start);
  double energy_max = g_record.energy_start;   // J
  for (int k = 0; k < planned; ++k) {
    const double c0 = thread_cpu_us();
    const auto t0 = std::chrono::steady_clock::now();
    world->step();
    const auto t1 = std::chrono::steady_clock::now();
    cpu_us.push_back(thread_cpu_us() - c0);
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    g_record.steps = k + 1;
    if (!last && world->out_of_room()) break;
    world->read(now);
    if (!finite(now)) {
      set_failed("non-finite state at step " + std::to_string(k + 1));
      break;
    }
    energy_max = std::max(energy_max, energy(now));
    for (std::size_t i = 0; i < now.size(); ++i) g_record.thrown = std::max(g_record.thrown, now[i].p[2] - start[i].p[2]);
  }
  g_record.rss_mb = (status_kb("VmHWM:") - rss_before) / 1024.0;
  g_record.energy_rise = energy_max - g_record.energy_start;
  if (!g_record.failed[0]) end_outcome(start, now);
  g_record.cpu_us_median = median(cpu_us);
  step_statistics(std::move(us));
  const std::string trouble = world->trouble();
  if (!trouble.empty()) set_failed(g_record.failed[0] ? std::string(g_record.failed) + "; " + trouble : trouble);
  if (g_verbose && !world->notes().empty()) std::fprintf(stderr, "  %s: %s\n", engine.c_str(), world->notes().c_str());
  return !world->out_of_room();
}

// The run, retried with more room for contacts while the engine runs out of it: MuJoCo 2.2's
// arena is sized when the model is compiled, so its user raises <size> until the warnings stop.
// Contacts per box tried after the engine's default (Scene::room 0); the last try stands, failed.
constexpr int kRooms[] = {0, 2, 3, 4, 6, 8, 12, 16, 24, 32};

void measure(const std::string& engine, Scene scene, double duration) {
  for (int room : kRooms) {
    if (room < scene.room) continue;
    scene.room = room;
    if (run_once(engine, scene, duration, room == kRooms[std::size(kRooms) - 1])) return;
  }
}

// ---- the parent: runs, repeats, rows -------------------------------------------------------

std::string describe_exit(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    return std::string("killed by signal ") + std::to_string(sig) + " (" + strsignal(sig) + ")" +
           (sig == SIGKILL ? ", out of memory?" : "");
  }
  return "exited with code " + std::to_string(WEXITSTATUS(status)) + " before reporting";
}

// One run in a child process; its record, or a failed one saying how the child ended.
Record run_in_child(const std::string& engine, const Scene& scene, double duration) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fds[0]);
    g_pipe = fds[1];
    // Counted from the address space the child has (a sanitizer build reserves terabytes).
    const auto most = static_cast<rlim_t>(1024.0 * status_kb("VmSize:") + kChildGrowth);
    const rlimit limit{most, most};
    setrlimit(RLIMIT_AS, &limit);
    try {
      measure(engine, scene, duration);
    } catch (const std::bad_alloc&) {
      set_failed("out of memory (std::bad_alloc)");
    } catch (const std::exception& e) {
      set_failed(std::string("exception: ") + e.what());
    }
    send_record_and_exit(0);
  }
  close(fds[1]);
  Record record;
  std::size_t got = 0;
  char* p = reinterpret_cast<char*>(&record);
  while (got < sizeof record) {
    const ssize_t n = read(fds[0], p + got, sizeof record - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != sizeof record) {
    record = Record{};
    std::snprintf(record.failed, sizeof record.failed, "%s", describe_exit(status).c_str());
  }
  return record;
}

// One row: the step times are the median over repeats of each run's median, min and max; the
// outcome is the first run's (each engine here is deterministic, every repeat computes the same
// states: a difference is reported on stderr); a run that failed makes the row failed.
struct Row {
  std::string engine, layout, failed = "no";
  int n = 0, rate = 0, steps = 0;
  double gap = 0, duration = 0;
  Record outcome;
  double us_median = NAN, us_min = NAN, us_max = NAN, rss_mb = NAN;   // us, MB
  double cpu_us_median = NAN;                                         // us: the step's thread CPU time, median
};

Row combine(const std::vector<Record>& runs) {
  Row row;
  row.outcome = runs.front();
  std::vector<double> med, lo, hi, rss, cpu;
  for (const Record& r : runs) {
    if (r.failed[0] && row.failed == "no") row.failed = r.failed;
    if (r.steps == 0 || r.us_median <= 0) continue;   // ended before its times were summed
    med.push_back(r.us_median);
    lo.push_back(r.us_min);
    hi.push_back(r.us_max);
    rss.push_back(r.rss_mb);
    cpu.push_back(r.cpu_us_median);
    const Record& a = row.outcome;
    if (r.steps != a.steps || r.energy_rise != a.energy_rise || r.drift_end != a.drift_end || r.thrown != a.thrown)
      std::fprintf(stderr, "graspsim_peers: the repeats' outcomes differ; the first one's is reported\n");
  }
  row.steps = row.outcome.steps;
  row.us_median = median(med);
  row.us_min = median(lo);
  row.us_max = median(hi);
  row.rss_mb = median(rss);
  row.cpu_us_median = median(cpu);
  return row;
}

// ---- output --------------------------------------------------------------------------------

constexpr const char* kCsvHeader =
    "engine,layout,n,rate,gap,duration,steps,us_step_median,us_step_min,us_step_max,cpu_us_step_median,us_body,rss_mb,"
    "energy_start_j,energy_rise_j,drift_end_m,speed_end_ms,thrown_m,failed";

void print_table_header() {
  std::printf("%-7s %-8s %5s %5s %6s %10s %21s %8s %9s %7s %9s %9s %8s %9s %8s  %s\n", "engine", "layout", "n",
              "Hz", "steps", "us/step", "(min - max)", "us/body", "cpu us", "RSS MB", "E0 J", "rise J", "drift m",
              "speed m/s", "thrown m", "failed");
}

void print_table_row(const Row& r) {
  char range[64];
  std::snprintf(range, sizeof range, "(%.1f - %.1f)", r.us_min, r.us_max);
  std::printf("%-7s %-8s %5d %5d %6d %10.1f %21s %8.3f %9.1f %7.2f %9.2f %9.3g %8.3g %9.3g %8.3g  %s\n",
              r.engine.c_str(), r.layout.c_str(), r.n, r.rate, r.steps, r.us_median, range, r.us_median / r.n,
              r.cpu_us_median, r.rss_mb,
              r.outcome.energy_start, r.outcome.energy_rise, r.outcome.drift_end, r.outcome.speed_end,
              r.outcome.thrown, r.failed.c_str());
  std::fflush(stdout);
}

// A CSV field: quoted (quotes doubled) when it holds a comma, a quote or a line break.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

void write_csv_row(std::FILE* f, const Row& r) {
  const Record& o = r.outcome;
  std::fprintf(f, "%s,%s,%d,%d,%.17g,%.17g,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.9g,%.6g,%.6g,%.6g,%.6g,%s\n",
               r.engine.c_str(), r.layout.c_str(), r.n, r.rate, r.gap, r.duration, r.steps, r.us_median, r.us_min,
               r.us_max, r.cpu_us_median, r.us_median / r.n, r.rss_mb, o.energy_start, o.energy_rise, o.drift_end, o.speed_end, o.thrown,
               csv_field(r.failed).c_str());
  std::fflush(f);
}

// ---- options -------------------------------------------------------------------------------

constexpr const char* kUsage =
    "usage: graspsim_peers [--engines graspsim,ode,mujoco,bullet] [--layouts apart,island,tower,pyramid,pile]\n"
    "                      [--n 16,64,144,400,1000] [--rates 50,500,3000] [--gap M] [--duration S]\n"
    "                      [--repeats R] [--csv FILE] [--sleep] [--verbose]\n"
    "  --n: boxes asked for (a pyramid takes the largest triangular number below); --rates in Hz;\n"
    "  --gap in m between touching boxes; --duration in simulated s (default 2); --repeats\n"
    "  (default 3), each run in a child process of its own; --sleep leaves Bullet's deactivation on.\n";

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  if (out.empty()) throw std::invalid_argument("empty list");
  return out;
}

double parse_number(const std::string& s) {
  char* end = nullptr;
  const double x = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(x)) throw std::invalid_argument("not a number: " + s);
  return x;
}

int parse_positive(const std::string& s) {
  const double x = parse_number(s);
  if (x < 1 || x != std::floor(x) || x > 1e7) throw std::invalid_argument("not a positive integer: " + s);
  return static_cast<int>(x);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--sleep") { o.sleep = true; continue; }
    if (arg == "--verbose") { o.verbose = true; continue; }
    if (arg == "--help" || arg == "-h") { std::fputs(kUsage, stdout); std::exit(0); }
    if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value (or is unknown)");
    const std::string value = argv[++i];
    if (arg == "--engines") {
      o.engines = split(value);
      const std::vector<std::string> known = available_engines();
      for (const std::string& e : o.engines)
        if (std::find(known.begin(), known.end(), e) == known.end())
          throw std::invalid_argument("unknown engine " + e + " (this build has: " + join(known) + ")");
    } else if (arg == "--layouts") {
      o.layouts.clear();
      for (const std::string& name : split(value)) {
        scale::Layout l;
        if (!scale::parse_layout(name, l)) throw std::invalid_argument("unknown layout " + name);
        o.layouts.push_back(l);
      }
    } else if (arg == "--n" || arg == "--rates") {
      std::vector<int>& list = arg == "--n" ? o.n : o.rates;
      list.clear();
      for (const std::string& item : split(value)) list.push_back(parse_positive(item));
    } else if (arg == "--gap") {
      o.gap = parse_number(value);
      if (o.gap < 0) throw std::invalid_argument("--gap must be >= 0");
    } else if (arg == "--duration") {
      o.duration = parse_number(value);
      if (o.duration <= 0) throw std::invalid_argument("--duration must be > 0");
    } else if (arg == "--repeats") {
      o.repeats = parse_positive(value);
    } else if (arg == "--csv") {
      o.csv = value;
    } else {
      throw std::invalid_argument("unknown option " + arg);
    }
  }
  return o;
}

int run(const Options& o) {
  std::FILE* csv = nullptr;
  if (!o.csv.empty()) {
    csv = std::fopen(o.csv.c_str(), "w");
    if (!csv) throw std::runtime_error("cannot write " + o.csv);
    std::fprintf(csv, "%s\n", kCsvHeader);
  }
  g_verbose = o.verbose;
  print_table_header();
  for (const std::string& engine : o.engines)
    for (scale::Layout layout : o.layouts)
      for (int n : o.n)
        for (int rate : o.rates) {
          Scene scene;
          scene.boxes = scale::layout_boxes(layout, n, o.gap);
          scene.dt = 1.0 / rate;
          scene.sleep = o.sleep;
          std::vector<Record> runs;
          for (int r = 0; r < o.repeats; ++r) {
            runs.push_back(run_in_child(engine, scene, o.duration));
            scene.room = runs.back().room;   // later repeats start from the room the first needed
          }
          Row row = combine(runs);
          row.engine = engine;
          row.layout = scale::layout_name(layout);
          row.n = static_cast<int>(scene.boxes.size());
          row.rate = rate;
          row.gap = o.gap;
          row.duration = o.duration;
          print_table_row(row);
          if (csv) write_csv_row(csv, row);
        }
  if (csv) std::fclose(csv);
  return 0;
}

}  // namespace

[[noreturn]] void fail_run(const std::string& why) {
  set_failed(why);
  send_record_and_exit(2);
}

}  // namespace graspsim::bench::peers

int main(int argc, char** argv) {
  using namespace graspsim::bench::peers;
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "graspsim_peers: %s\n%s", e.what(), kUsage);
    return 2;
  }
}
