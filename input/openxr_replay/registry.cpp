// The handle registry, the environment switches and small helpers shared by the topic files.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <unordered_map>

#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {
namespace {

struct Registry {
    std::unordered_map<std::uint64_t, std::unique_ptr<Object>> objects;
    std::uint64_t next = 1;
};

Registry& registry()
{
    static Registry r;
    return r;
}

// Handles are small multiples of a large odd stride with a tag in the top bits, so a stale
// or made-up handle is unlikely to name a live object, and never dereferenced either way.
constexpr std::uint64_t kHandleTag = 0x4C0B000000000000ull;

const char* env(const char* name)
{
    const char* v = std::getenv(name);
    return (v && *v) ? v : nullptr;
}

bool env_flag(const char* name)
{
    const char* v = env(name);
    return v && std::strcmp(v, "0") != 0;
}

long env_long(const char* name, long fallback, long min, bool report)
{
    const char* v = env(name);
    if (!v) return fallback;
    errno = 0;
    char* end = nullptr;
    const long n = std::strtol(v, &end, 10);
    if (errno != 0 || end == v || *end != '\0' || n < min) {
        if (report) log_line(std::string(name) + "=" + v + " is not a whole number >= " + std::to_string(min) + "; ignored");
        return fallback;
    }
    return n;
}

} // namespace

std::recursive_mutex& api_mutex()
{
    static std::recursive_mutex m;
    return m;
}

std::uint64_t add_object(std::unique_ptr<Object> obj, std::uint64_t parent)
{
    Registry& r = registry();
    const std::uint64_t h = kHandleTag | (r.next++ * 0x10001ull);
    obj->handle = h;
    obj->parent = parent;
    r.objects.emplace(h, std::move(obj));
    return h;
}

Object* find_object(std::uint64_t handle, Kind kind)
{
    Registry& r = registry();
    auto it = r.objects.find(handle);
    if (it == r.objects.end() || it->second->kind != kind) return nullptr;
    return it->second.get();
}

std::vector<std::uint64_t> children_of(std::uint64_t parent, Kind kind)
{
    std::vector<std::uint64_t> out;
    for (const auto& [h, o] : registry().objects)
        if (o->parent == parent && o->kind == kind) out.push_back(h);
    std::sort(out.begin(), out.end());
    return out;
}

void destroy_object(std::uint64_t handle)
{
    Registry& r = registry();
    std::vector<std::uint64_t> kids;
    for (const auto& [h, o] : r.objects)
        if (o->parent == handle) kids.push_back(h);
    std::sort(kids.begin(), kids.end());
    // Swapchains, spaces and trackers before the session that owns their GPU resources.
    for (std::uint64_t k : kids) destroy_object(k);
    auto it = r.objects.find(handle);
    if (it == r.objects.end()) return;
    Object* o = it->second.get();
    if (o->kind == Kind::Swapchain) {
        auto* sc = static_cast<Swapchain*>(o);
        if (Session* s = find<Session>(sc->session, Kind::Session)) destroy_swapchain_images(*s, *sc);
    } else if (o->kind == Kind::Session) {
        release_vulkan_session(*static_cast<Session*>(o));
        if (Instance* inst = find<Instance>(static_cast<Session*>(o)->instance, Kind::Instance))
            if (inst->session == handle) inst->session = 0;
    }
    r.objects.erase(handle);
}

Switches read_switches(bool report_problems)
{
    Switches s;
    if (const char* v = env("LOBESKETCH_REPLAY")) s.recording_path = v;
    if (const char* v = env("LOBESKETCH_REPLAY_DUMP")) s.dump_dir = v;
    s.dump_every = env_long("LOBESKETCH_REPLAY_DUMP_EVERY", 1, 1, report_problems);
    s.max_frames = env_long("LOBESKETCH_REPLAY_MAX_FRAMES", 0, 1, report_problems);
    s.lose_session_at = env_long("LOBESKETCH_REPLAY_LOSE_SESSION_AT", -1, 0, report_problems);
    s.hand_tracking = !env_flag("LOBESKETCH_REPLAY_NO_HAND_TRACKING");
    s.vulkan = !env_flag("LOBESKETCH_REPLAY_NO_VULKAN");
    s.realtime = env_flag("LOBESKETCH_REPLAY_REALTIME");
    if (const char* v = env("LOBESKETCH_REPLAY_VIEW_SIZE")) {
        unsigned w = 0, h = 0;
        char extra = 0;
        if (std::sscanf(v, "%ux%u%c", &w, &h, &extra) == 2 && w >= 1 && h >= 1 && w <= 4096 && h <= 4096) {
            s.view_width = w;
            s.view_height = h;
        } else if (report_problems) {
            log_line(std::string("LOBESKETCH_REPLAY_VIEW_SIZE=") + v + " is not WxH with sides 1 to 4096; ignored");
        }
    }
    return s;
}

void log_line(const std::string& line)
{
    std::fprintf(stderr, "lobesketch_xr_replay: %s\n", line.c_str());
    std::fflush(stderr);
}

XrResult copy_string(const std::string& s, std::uint32_t capacity, std::uint32_t* count_out, char* buffer)
{
    if (!count_out) return XR_ERROR_VALIDATION_FAILURE;
    *count_out = static_cast<std::uint32_t>(s.size() + 1);
    if (capacity == 0) return XR_SUCCESS;
    if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
    if (capacity < s.size() + 1) return XR_ERROR_SIZE_INSUFFICIENT;
    std::memcpy(buffer, s.c_str(), s.size() + 1);
    return XR_SUCCESS;
}

const void* find_in_chain(const void* next, XrStructureType type)
{
    // Bounded walk: a looping chain cannot hang the runtime.
    for (int i = 0; next && i < 64; ++i) {
        const auto* h = static_cast<const XrBaseInStructure*>(next);
        if (h->type == type) return h;
        next = h->next;
    }
    return nullptr;
}

void* find_in_chain_mut(void* next, XrStructureType type)
{
    for (int i = 0; next && i < 64; ++i) {
        auto* h = static_cast<XrBaseOutStructure*>(next);
        if (h->type == type) return h;
        next = h->next;
    }
    return nullptr;
}

namespace {

XrQuaternionf qmul(const XrQuaternionf& a, const XrQuaternionf& b)
{
    return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

XrVector3f rotate(const XrQuaternionf& q, const XrVector3f& v)
{
    const XrQuaternionf p{v.x, v.y, v.z, 0};
    const XrQuaternionf c{-q.x, -q.y, -q.z, q.w};
    const XrQuaternionf r = qmul(qmul(q, p), c);
    return {r.x, r.y, r.z};
}

} // namespace

RigidPose compose(const RigidPose& a, const RigidPose& b)
{
    RigidPose r;
    r.orientation = qmul(a.orientation, b.orientation);
    const XrVector3f t = rotate(a.orientation, b.position);
    r.position = {a.position.x + t.x, a.position.y + t.y, a.position.z + t.z};
    return r;
}

RigidPose inverse(const RigidPose& a)
{
    RigidPose r;
    r.orientation = {-a.orientation.x, -a.orientation.y, -a.orientation.z, a.orientation.w};
    const XrVector3f t = rotate(r.orientation, a.position);
    r.position = {-t.x, -t.y, -t.z};
    return r;
}

bool pose_valid(const XrPosef& p)
{
    const float v[] = {p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w,
                       p.position.x,    p.position.y,    p.position.z};
    for (float f : v)
        if (!std::isfinite(f)) return false;
    const float n = p.orientation.x * p.orientation.x + p.orientation.y * p.orientation.y +
                    p.orientation.z * p.orientation.z + p.orientation.w * p.orientation.w;
    return std::fabs(n - 1.0f) <= 0.01f;
}

RigidPose to_rigid(const XrPosef& p)
{
    return {p.orientation, p.position};
}

XrPosef to_xr(const RigidPose& p)
{
    return {p.orientation, p.position};
}

XrResult validate_time(XrTime t)
{
    return t > 0 ? XR_SUCCESS : XR_ERROR_TIME_INVALID;
}

} // namespace lobe::xrr
