// Session lifecycle, the frame loop (time advances one recorded frame per xrWaitFrame),
// views and reference spaces.

#include <algorithm>
#include <thread>

#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {
namespace {

/// Frame period after the last frame (or of a one-frame recording): the header's rate.
XrDuration nominal_period(const Instance& inst)
{
    const double hz = inst.recording.header.nominal_rate_hz;
    return (hz >= 1.0 && hz <= 1000.0) ? static_cast<XrDuration>(1e9 / hz) : 11'111'111;
}

XrTime time_of_frame(const Instance& inst, std::int64_t f)
{
    const auto n = static_cast<std::int64_t>(inst.frame_count);
    if (f < n) return inst.frame_times[static_cast<std::size_t>(f)];
    return inst.frame_times.back() + (f - n + 1) * nominal_period(inst);
}

/// Leaves the running states towards STOPPING (spec: FOCUSED → VISIBLE → SYNCHRONIZED → STOPPING).
void begin_stopping(Instance& inst, Session& s, XrTime t)
{
    s.exit_requested = true;
    if (s.state == XR_SESSION_STATE_FOCUSED) queue_state(inst, s, XR_SESSION_STATE_VISIBLE, t);
    if (s.state == XR_SESSION_STATE_VISIBLE) queue_state(inst, s, XR_SESSION_STATE_SYNCHRONIZED, t);
    if (s.state == XR_SESSION_STATE_READY) queue_state(inst, s, XR_SESSION_STATE_SYNCHRONIZED, t);
    if (s.state == XR_SESSION_STATE_SYNCHRONIZED) queue_state(inst, s, XR_SESSION_STATE_STOPPING, t);
}

bool is_known_reference(XrReferenceSpaceType t)
{
    return t == XR_REFERENCE_SPACE_TYPE_VIEW || t == XR_REFERENCE_SPACE_TYPE_LOCAL || t == XR_REFERENCE_SPACE_TYPE_STAGE;
}

constexpr XrSpaceLocationFlags kValid = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
constexpr XrSpaceLocationFlags kAll = kValid | XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;

XrResult check_swapchain_image(const Session& s, const XrSwapchainSubImage& sub, Swapchain*& sc)
{
    sc = find<Swapchain>(key(sub.swapchain), Kind::Swapchain);
    if (!sc || sc->session != s.handle) return XR_ERROR_HANDLE_INVALID;
    if (sc->last_released < 0) return XR_ERROR_LAYER_INVALID;
    const auto& r = sub.imageRect;
    if (r.offset.x < 0 || r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
        static_cast<std::int64_t>(r.offset.x) + r.extent.width > static_cast<std::int64_t>(sc->info.width) ||
        static_cast<std::int64_t>(r.offset.y) + r.extent.height > static_cast<std::int64_t>(sc->info.height))
        return XR_ERROR_SWAPCHAIN_RECT_INVALID;
    if (sub.imageArrayIndex >= sc->info.arraySize) return XR_ERROR_VALIDATION_FAILURE;
    return XR_SUCCESS;
}

XrResult check_layer_space(const Session& s, XrSpace space)
{
    const Space* sp = find<Space>(key(space), Kind::Space);
    return (sp && sp->session == s.handle) ? XR_SUCCESS : XR_ERROR_HANDLE_INVALID;
}

} // namespace

void queue_state(Instance& inst, Session& s, XrSessionState state, XrTime time)
{
    s.state = state;
    Event e{XR_TYPE_EVENT_DATA_BUFFER};
    auto* c = reinterpret_cast<XrEventDataSessionStateChanged*>(&e);
    c->type = XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED;
    c->next = nullptr;
    c->session = as_handle<XrSession>(s.handle);
    c->state = state;
    c->time = time;
    inst.events.push_back(e);
}

std::size_t frame_at(const Instance& inst, XrTime time)
{
    const auto end = inst.frame_times.begin() + static_cast<std::ptrdiff_t>(inst.frame_count);
    auto it = std::upper_bound(inst.frame_times.begin(), end, time);
    if (it == inst.frame_times.begin()) return 0;
    return static_cast<std::size_t>(it - inst.frame_times.begin()) - 1;
}

Located locate_in_stage(const Instance& inst, const Space& space, XrTime time)
{
    Located base;
    if (space.action != 0) return base; // no controllers: action spaces are never located
    switch (space.reference) {
    case XR_REFERENCE_SPACE_TYPE_STAGE: base.flags = kAll; break;
    case XR_REFERENCE_SPACE_TYPE_LOCAL:
        base.pose = inst.local_origin;
        base.flags = kAll;
        break;
    case XR_REFERENCE_SPACE_TYPE_VIEW: base = inst.heads[frame_at(inst, time)]; break;
    default: return base;
    }
    base.pose = compose(base.pose, space.offset);
    return base;
}

bool session_checks(XrSession session, Session*& s, Instance*& inst, XrResult& r)
{
    s = find<Session>(key(session), Kind::Session);
    inst = s ? find<Instance>(s->instance, Kind::Instance) : nullptr;
    if (!s || !inst) {
        r = XR_ERROR_HANDLE_INVALID;
        return false;
    }
    if (s->lost) {
        r = XR_ERROR_SESSION_LOST;
        return false;
    }
    r = XR_SUCCESS;
    return true;
}

XrResult XRAPI_CALL xrCreateSession(XrInstance instance, const XrSessionCreateInfo* info, XrSession* out)
{
    return guarded("xrCreateSession", [&]() -> XrResult {
        Instance* inst = find<Instance>(key(instance), Kind::Instance);
        if (!inst) return XR_ERROR_HANDLE_INVALID;
        if (!info || !out || info->type != XR_TYPE_SESSION_CREATE_INFO || info->createFlags != 0)
            return XR_ERROR_VALIDATION_FAILURE;
        if (info->systemId != kSystemId) return XR_ERROR_SYSTEM_INVALID;
        if (inst->session != 0) return XR_ERROR_LIMIT_REACHED;
        auto s = std::make_unique<Session>();
        s->instance = inst->handle;
        const auto* binding = inst->ext_vulkan2 ? static_cast<const XrGraphicsBindingVulkanKHR*>(
                                                      find_in_chain(info->next, XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR))
                                                : nullptr;
        Session& ref = *s;
        const std::uint64_t h = add_object(std::move(s), inst->handle);
        if (binding) {
            XrResult r = inst->graphics_requirements_queried ? bind_vulkan_session(*inst, ref, *binding)
                                                            : XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING;
            if (r != XR_SUCCESS) {
                destroy_object(h);
                return r;
            }
        } else if (inst->ext_headless) {
            ref.headless = true;
        } else {
            destroy_object(h);
            return XR_ERROR_GRAPHICS_DEVICE_INVALID;
        }
        inst->session = h;
        const XrTime t = time_of_frame(*inst, std::max<std::int64_t>(inst->next_frame, 0));
        queue_state(*inst, ref, XR_SESSION_STATE_IDLE, t);
        if (static_cast<std::size_t>(inst->next_frame) >= inst->frame_count) {
            // Nothing left to play: this session goes straight to EXITING.
            ref.exit_requested = true;
            queue_state(*inst, ref, XR_SESSION_STATE_EXITING, t);
        } else {
            queue_state(*inst, ref, XR_SESSION_STATE_READY, t);
        }
        *out = as_handle<XrSession>(h);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroySession(XrSession session)
{
    return guarded("xrDestroySession", [&]() -> XrResult {
        Session* s = find<Session>(key(session), Kind::Session);
        if (!s) return XR_ERROR_HANDLE_INVALID;
        if (Instance* inst = find<Instance>(s->instance, Kind::Instance)) {
            // Events of a destroyed session are dropped (the spec lets them go).
            std::erase_if(inst->events, [&](const Event& e) {
                const auto* c = reinterpret_cast<const XrEventDataSessionStateChanged*>(&e);
                return c->type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED && key(c->session) == s->handle;
            });
        }
        destroy_object(s->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrBeginSession(XrSession session, const XrSessionBeginInfo* info)
{
    return guarded("xrBeginSession", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_SESSION_BEGIN_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (s->running) return XR_ERROR_SESSION_RUNNING;
        if (s->state != XR_SESSION_STATE_READY) return XR_ERROR_SESSION_NOT_READY;
        if (!s->headless && info->primaryViewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
            return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
        s->running = true;
        s->frame_waited = s->frame_begun = false;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEndSession(XrSession session)
{
    return guarded("xrEndSession", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
        if (s->state != XR_SESSION_STATE_STOPPING) return XR_ERROR_SESSION_NOT_STOPPING;
        s->running = false;
        s->frame_waited = s->frame_begun = false;
        const XrTime t = time_of_frame(*inst, std::max<std::int64_t>(s->frame_index, 0));
        queue_state(*inst, *s, XR_SESSION_STATE_IDLE, t);
        if (s->exit_requested) queue_state(*inst, *s, XR_SESSION_STATE_EXITING, t);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrRequestExitSession(XrSession session)
{
    return guarded("xrRequestExitSession", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
        begin_stopping(*inst, *s, time_of_frame(*inst, std::max<std::int64_t>(s->frame_index, 0)));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrWaitFrame(XrSession session, const XrFrameWaitInfo* info, XrFrameState* state)
{
    std::chrono::steady_clock::time_point wake{};
    const XrResult result = guarded("xrWaitFrame", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (s->loss_pending) {
            s->lost = true;
            return XR_ERROR_SESSION_LOST;
        }
        if (info && info->type != XR_TYPE_FRAME_WAIT_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!state || state->type != XR_TYPE_FRAME_STATE) return XR_ERROR_VALIDATION_FAILURE;
        if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
        const std::int64_t f = inst->next_frame++;
        const XrTime t = time_of_frame(*inst, f);
        if (s->state == XR_SESSION_STATE_READY && !s->exit_requested) {
            // The frame loop is synchronized with the first xrWaitFrame: show and focus at once.
            queue_state(*inst, *s, XR_SESSION_STATE_SYNCHRONIZED, t);
            queue_state(*inst, *s, XR_SESSION_STATE_VISIBLE, t);
            queue_state(*inst, *s, XR_SESSION_STATE_FOCUSED, t);
            s->wall_start = std::chrono::steady_clock::now();
        }
        if (inst->sw.lose_session_at >= 0 && !inst->lost_once && f >= inst->sw.lose_session_at) {
            // Test switch: the headset goes away. This frame still completes; the next
            // session call answers XR_ERROR_SESSION_LOST.
            inst->lost_once = true;
            s->loss_pending = true;
            queue_state(*inst, *s, XR_SESSION_STATE_LOSS_PENDING, t);
        } else if (static_cast<std::size_t>(f) >= inst->frame_count && !s->exit_requested) {
            begin_stopping(*inst, *s, t); // the recording is over
        }
        s->frame_index = f;
        s->frame_time = t;
        s->frame_waited = true;
        state->predictedDisplayTime = t;
        state->predictedDisplayPeriod = time_of_frame(*inst, f + 1) - t;
        state->shouldRender =
            (s->state == XR_SESSION_STATE_VISIBLE || s->state == XR_SESSION_STATE_FOCUSED) ? XR_TRUE : XR_FALSE;
        if (inst->sw.realtime) wake = s->wall_start + std::chrono::nanoseconds(t - inst->frame_times.front());
        return XR_SUCCESS;
    });
    if (result == XR_SUCCESS && wake != std::chrono::steady_clock::time_point{}) {
        // Pace without the lock; never more than one nominal second at a time.
        const auto now = std::chrono::steady_clock::now();
        if (wake > now) std::this_thread::sleep_until(std::min(wake, now + std::chrono::seconds(1)));
    }
    return result;
}

XrResult XRAPI_CALL xrBeginFrame(XrSession session, const XrFrameBeginInfo* info)
{
    return guarded("xrBeginFrame", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (info && info->type != XR_TYPE_FRAME_BEGIN_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
        if (!s->frame_waited) return XR_ERROR_CALL_ORDER_INVALID;
        s->frame_waited = false;
        const bool discarded = s->frame_begun;
        s->frame_begun = true;
        return discarded ? XR_FRAME_DISCARDED : XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEndFrame(XrSession session, const XrFrameEndInfo* info)
{
    return guarded("xrEndFrame", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_FRAME_END_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
        if (!s->frame_begun) return XR_ERROR_CALL_ORDER_INVALID;
        if (validate_time(info->displayTime) != XR_SUCCESS) return XR_ERROR_TIME_INVALID;
        if (info->environmentBlendMode != XR_ENVIRONMENT_BLEND_MODE_OPAQUE) return XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED;
        if (info->layerCount > kMaxLayers) return XR_ERROR_LAYER_LIMIT_EXCEEDED;
        if (info->layerCount > 0 && !info->layers) return XR_ERROR_LAYER_INVALID;
        const XrCompositionLayerProjection* first_projection = nullptr;
        for (std::uint32_t i = 0; i < info->layerCount; ++i) {
            const XrCompositionLayerBaseHeader* layer = info->layers[i];
            if (!layer) return XR_ERROR_LAYER_INVALID;
            if (layer->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
                const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(layer);
                if (XrResult e = check_layer_space(*s, p->space); e != XR_SUCCESS) return e;
                if (p->viewCount != kViewCount || !p->views) return XR_ERROR_VALIDATION_FAILURE;
                for (std::uint32_t v = 0; v < p->viewCount; ++v) {
                    const XrCompositionLayerProjectionView& view = p->views[v];
                    if (view.type != XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW) return XR_ERROR_VALIDATION_FAILURE;
                    if (!pose_valid(view.pose)) return XR_ERROR_POSE_INVALID;
                    Swapchain* sc;
                    if (XrResult e = check_swapchain_image(*s, view.subImage, sc); e != XR_SUCCESS) return e;
                }
                if (!first_projection) first_projection = p;
            } else if (layer->type == XR_TYPE_COMPOSITION_LAYER_QUAD) {
                const auto* q = reinterpret_cast<const XrCompositionLayerQuad*>(layer);
                if (XrResult e = check_layer_space(*s, q->space); e != XR_SUCCESS) return e;
                if (!pose_valid(q->pose)) return XR_ERROR_POSE_INVALID;
                Swapchain* sc;
                if (XrResult e = check_swapchain_image(*s, q->subImage, sc); e != XR_SUCCESS) return e;
            } else {
                return XR_ERROR_LAYER_INVALID;
            }
        }
        s->frame_begun = false;
        if (first_projection && !inst->sw.dump_dir.empty() && s->frame_index >= 0 &&
            static_cast<std::size_t>(s->frame_index) < inst->frame_count && s->frame_index % inst->sw.dump_every == 0)
            dump_projection(*inst, *s, *first_projection, s->frame_index);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrLocateViews(XrSession session, const XrViewLocateInfo* info, XrViewState* view_state,
                                  uint32_t capacity, uint32_t* count, XrView* views)
{
    return guarded("xrLocateViews", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_VIEW_LOCATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!view_state || view_state->type != XR_TYPE_VIEW_STATE || !count) return XR_ERROR_VALIDATION_FAILURE;
        if (info->viewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
            return XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
        if (validate_time(info->displayTime) != XR_SUCCESS) return XR_ERROR_TIME_INVALID;
        const Space* base = find<Space>(key(info->space), Kind::Space);
        if (!base || base->session != s->handle) return XR_ERROR_HANDLE_INVALID;
        *count = kViewCount;
        if (capacity == 0) return XR_SUCCESS;
        if (!views) return XR_ERROR_VALIDATION_FAILURE;
        if (capacity < kViewCount) return XR_ERROR_SIZE_INSUFFICIENT;
        for (std::uint32_t i = 0; i < kViewCount; ++i)
            if (views[i].type != XR_TYPE_VIEW) return XR_ERROR_VALIDATION_FAILURE;
        const Located head = inst->heads[frame_at(*inst, info->displayTime)];
        const Located b = locate_in_stage(*inst, *base, info->displayTime);
        view_state->viewStateFlags = 0;
        const XrFovf fov{-0.7854f, 0.7854f, 0.7854f, -0.7854f}; // 90° × 90°
        for (std::uint32_t i = 0; i < kViewCount; ++i) {
            views[i].pose = XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
            views[i].fov = fov;
        }
        if ((b.flags & kValid) != kValid) return XR_SUCCESS;
        const RigidPose head_in_base = compose(inverse(b.pose), head.pose);
        for (std::uint32_t i = 0; i < kViewCount; ++i) {
            RigidPose eye;
            eye.position = {i == 0 ? -kHalfIpd : kHalfIpd, 0.0f, 0.0f};
            views[i].pose = to_xr(compose(head_in_base, eye));
        }
        view_state->viewStateFlags = head.flags & b.flags;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrEnumerateReferenceSpaces(XrSession session, uint32_t capacity, uint32_t* count,
                                               XrReferenceSpaceType* spaces)
{
    return guarded("xrEnumerateReferenceSpaces", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        return enumerate(std::vector<XrReferenceSpaceType>{XR_REFERENCE_SPACE_TYPE_VIEW, XR_REFERENCE_SPACE_TYPE_LOCAL,
                                                           XR_REFERENCE_SPACE_TYPE_STAGE},
                         capacity, count, spaces);
    });
}

XrResult XRAPI_CALL xrCreateReferenceSpace(XrSession session, const XrReferenceSpaceCreateInfo* info, XrSpace* out)
{
    return guarded("xrCreateReferenceSpace", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || !out || info->type != XR_TYPE_REFERENCE_SPACE_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!is_known_reference(info->referenceSpaceType)) return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
        if (!pose_valid(info->poseInReferenceSpace)) return XR_ERROR_POSE_INVALID;
        auto sp = std::make_unique<Space>();
        sp->session = s->handle;
        sp->reference = info->referenceSpaceType;
        sp->offset = to_rigid(info->poseInReferenceSpace);
        *out = as_handle<XrSpace>(add_object(std::move(sp), s->handle));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetReferenceSpaceBoundsRect(XrSession session, XrReferenceSpaceType type, XrExtent2Df* bounds)
{
    return guarded("xrGetReferenceSpaceBoundsRect", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!bounds) return XR_ERROR_VALIDATION_FAILURE;
        if (!is_known_reference(type)) return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
        if (type == XR_REFERENCE_SPACE_TYPE_STAGE) {
            *bounds = {4.0f, 4.0f};
            return XR_SUCCESS;
        }
        *bounds = {0.0f, 0.0f};
        return XR_SPACE_BOUNDS_UNAVAILABLE;
    });
}

XrResult XRAPI_CALL xrLocateSpace(XrSpace space, XrSpace base_space, XrTime time, XrSpaceLocation* location)
{
    return guarded("xrLocateSpace", [&]() -> XrResult {
        const Space* a = find<Space>(key(space), Kind::Space);
        const Space* b = find<Space>(key(base_space), Kind::Space);
        if (!a || !b) return XR_ERROR_HANDLE_INVALID;
        if (a->session != b->session) return XR_ERROR_VALIDATION_FAILURE;
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(as_handle<XrSession>(a->session), s, inst, r)) return r;
        if (validate_time(time) != XR_SUCCESS) return XR_ERROR_TIME_INVALID;
        if (!location || location->type != XR_TYPE_SPACE_LOCATION) return XR_ERROR_VALIDATION_FAILURE;
        if (auto* v = static_cast<XrSpaceVelocity*>(find_in_chain_mut(location->next, XR_TYPE_SPACE_VELOCITY))) {
            v->velocityFlags = 0;
            v->linearVelocity = {0, 0, 0};
            v->angularVelocity = {0, 0, 0};
        }
        const Located la = locate_in_stage(*inst, *a, time);
        const Located lb = locate_in_stage(*inst, *b, time);
        location->locationFlags = 0;
        location->pose = XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
        if ((la.flags & kValid) != kValid || (lb.flags & kValid) != kValid) return XR_SUCCESS;
        location->pose = to_xr(compose(inverse(lb.pose), la.pose));
        location->locationFlags = la.flags & lb.flags;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroySpace(XrSpace space)
{
    return guarded("xrDestroySpace", [&]() -> XrResult {
        const Space* sp = find<Space>(key(space), Kind::Space);
        if (!sp) return XR_ERROR_HANDLE_INVALID;
        destroy_object(sp->handle);
        return XR_SUCCESS;
    });
}

} // namespace lobe::xrr
