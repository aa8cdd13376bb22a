#pragma once
/// \file fuzz_common.h
/// Shared by the libFuzzer targets (docs/fuzzing.md). A reader may refuse an input only with
/// one of the project's exceptions (core/errors.h) carrying a non-empty one-line message;
/// anything else (another exception, a crash, a sanitizer report, a timeout, a huge
/// allocation) is a finding, reported by libFuzzer.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh.h"
#include "input/recording.h"

namespace lobe::fuzz {

inline std::string as_string(const std::uint8_t* data, std::size_t size)
{
    return std::string(reinterpret_cast<const char*>(data), size);
}

/// Aborts (a finding) when a refusal's message is empty or spans several lines.
inline void check_one_line(const char* what)
{
    const std::string msg = what ? what : "";
    if (msg.empty() || msg.find('\n') != std::string::npos || msg.find('\r') != std::string::npos) {
        std::fprintf(stderr, "fuzz: the error message is not one line: \"%s\"\n", msg.c_str());
        std::abort();
    }
}

/// Aborts (a finding) unless `ok`; `what` names the broken promise.
inline void require(bool ok, const char* what)
{
    if (!ok) {
        std::fprintf(stderr, "fuzz: the reader broke its promise: %s\n", what);
        std::abort();
    }
}

/// A ReadReport's problems are one line each.
inline void check_report(const std::vector<std::string>& problems)
{
    for (const std::string& p : problems) check_one_line(p.c_str());
}

inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// What recording.h promises of a recording a reader returns: a frame or an event, frame times
/// finite and strictly increasing, event times non-decreasing, tracked positions finite.
inline void check_recording(const lobe::Recording& rec)
{
    require(!rec.frames.empty() || !rec.events.empty(), "a recording without frames or events");
    for (std::size_t i = 0; i < rec.frames.size(); ++i) {
        const lobe::HandFrame& f = rec.frames[i];
        require(std::isfinite(f.time), "a non-finite frame time");
        require(i == 0 || f.time > rec.frames[i - 1].time, "frame times not strictly increasing");
        require(!f.head_valid || finite(f.head.position), "a non-finite head position");
        for (const lobe::HandState& h : f.hands)
            if (h.active)
                for (const lobe::JointState& j : h.joints)
                    require(!j.position_valid() || finite(j.pose.position), "a non-finite joint position");
    }
    for (std::size_t i = 1; i < rec.events.size(); ++i)
        require(rec.events[i].time >= rec.events[i - 1].time, "event times going backwards");
}

/// What mesh_io.h promises of a mesh read_mesh returns: vertices and faces, finite
/// coordinates, every index in range.
inline void check_mesh(const lobe::TriangleMesh& m)
{
    require(!m.positions.empty() && !m.triangles.empty(), "a mesh without vertices or faces");
    const auto n = static_cast<long long>(m.positions.size());
    for (const glm::vec3& p : m.positions) require(finite(p), "a non-finite vertex");
    for (const auto& t : m.triangles)
        for (int v : t) require(v >= 0 && v < n, "a triangle index out of range");
    for (const auto& e : m.feature_edges)
        for (int v : e) require(v >= 0 && v < n, "a feature edge index out of range");
}

/// Runs `read` on one input: a lobe::Error with a one-line message is an expected outcome;
/// any other exception escapes to libFuzzer, which reports it.
template <class Read>
int run_reader(Read&& read)
{
    try {
        read();
    } catch (const lobe::Error& e) {
        check_one_line(e.what());
    }
    return 0;
}

} // namespace lobe::fuzz
