// Shared by the bench programs: clocks, latency statistics, CPU accounting, and the JSON shape of one
// measured row. Every bench program prints JSON lines (one object per row) on stdout; run.py collects
// them. Units are in the key names (_us, _per_s, _mb_s).
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <sys/resource.h>

#include <nlohmann/json.hpp>

namespace rr::bench {

/// Raises this process's open-file limit to its hard limit (a load generator holding 1,000 sockets
/// needs more than the usual soft limit of 1,024).
inline void raise_fd_limit() {
    rlimit r{};
    getrlimit(RLIMIT_NOFILE, &r);
    r.rlim_cur = r.rlim_max;
    setrlimit(RLIMIT_NOFILE, &r);
}

/// Wall clock in µs since the epoch (comparable across processes on one host).
inline double wall_clock_us() {
    return std::chrono::duration<double, std::micro>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// Microseconds between two steady_clock points.
inline double elapsed_us(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
    return std::chrono::duration<double, std::micro>(b - a).count();
}

/// Percentiles of a set of samples (µs). `q` in [0, 1]; nearest-rank. Empty: 0.
inline double percentile(std::vector<double> samples, double q) {
    if (samples.empty()) return 0;
    const auto k = static_cast<std::size_t>(q * double(samples.size() - 1) + 0.5);
    std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(k), samples.end());
    return samples[k];
}

/// CPU time and voluntary context switches of the process (getrusage(RUSAGE_SELF), the default) or of
/// the calling thread (RUSAGE_THREAD).
struct CpuSnapshot {
    double cpu_us = 0;
    long vcsw = 0;
    static CpuSnapshot now(int who = RUSAGE_SELF) {
        rusage u{};
        getrusage(who, &u);
        auto us = [](const timeval& t) { return double(t.tv_sec) * 1e6 + double(t.tv_usec); };
        return {us(u.ru_utime) + us(u.ru_stime), u.ru_nvcsw};
    }
};

/// One row of round-trip samples: p50/p99/max (µs), operations/s over the wall time, MB/s when
/// `bytes_per_op` (payload moved per operation, both directions) is non-zero, and the client's CPU µs
/// and voluntary context switches per operation.
inline nlohmann::json latency_row(const std::string& op, const std::vector<double>& samples_us, double wall_us,
                                  double bytes_per_op, const CpuSnapshot& before, const CpuSnapshot& after) {
    const double n = double(samples_us.size());
    nlohmann::json row = {{"op", op},
                          {"n", samples_us.size()},
                          {"p50_us", percentile(samples_us, 0.50)},
                          {"p99_us", percentile(samples_us, 0.99)},
                          {"max_us", samples_us.empty() ? 0.0 : *std::max_element(samples_us.begin(), samples_us.end())},
                          {"ops_per_s", wall_us > 0 ? n * 1e6 / wall_us : 0.0},
                          {"client_cpu_us_per_op", n > 0 ? (after.cpu_us - before.cpu_us) / n : 0.0},
                          {"client_vcsw_per_op", n > 0 ? double(after.vcsw - before.vcsw) / n : 0.0}};
    if (bytes_per_op > 0) row["mb_s"] = wall_us > 0 ? bytes_per_op * n / wall_us : 0.0;  // bytes/µs == MB/s
    return row;
}

}  // namespace rr::bench
