// XR_EXT_hand_tracking fed from the recording: the frame shown at a time is the last recorded
// frame not after it (no interpolation), with its joint poses, radii and flags as recorded.

#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {
namespace {

RigidPose joint_pose(const JointState& j)
{
    RigidPose p;
    p.position = {j.pose.position.x, j.pose.position.y, j.pose.position.z};
    p.orientation = {j.pose.orientation.x, j.pose.orientation.y, j.pose.orientation.z, j.pose.orientation.w};
    return p;
}

} // namespace

XrResult XRAPI_CALL xrCreateHandTrackerEXT(XrSession session, const XrHandTrackerCreateInfoEXT* info, XrHandTrackerEXT* out)
{
    return guarded("xrCreateHandTrackerEXT", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!inst->ext_hand_tracking) return XR_ERROR_FUNCTION_UNSUPPORTED;
        if (!info || !out || info->type != XR_TYPE_HAND_TRACKER_CREATE_INFO_EXT) return XR_ERROR_VALIDATION_FAILURE;
        if (info->hand != XR_HAND_LEFT_EXT && info->hand != XR_HAND_RIGHT_EXT) return XR_ERROR_VALIDATION_FAILURE;
        if (info->handJointSet != XR_HAND_JOINT_SET_DEFAULT_EXT) return XR_ERROR_VALIDATION_FAILURE;
        auto t = std::make_unique<HandTracker>();
        t->session = s->handle;
        t->hand = info->hand;
        *out = as_handle<XrHandTrackerEXT>(add_object(std::move(t), s->handle));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroyHandTrackerEXT(XrHandTrackerEXT tracker)
{
    return guarded("xrDestroyHandTrackerEXT", [&]() -> XrResult {
        HandTracker* t = find<HandTracker>(key(tracker), Kind::HandTracker);
        if (!t) return XR_ERROR_HANDLE_INVALID;
        destroy_object(t->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrLocateHandJointsEXT(XrHandTrackerEXT tracker, const XrHandJointsLocateInfoEXT* info,
                                          XrHandJointLocationsEXT* locations)
{
    return guarded("xrLocateHandJointsEXT", [&]() -> XrResult {
        HandTracker* t = find<HandTracker>(key(tracker), Kind::HandTracker);
        if (!t) return XR_ERROR_HANDLE_INVALID;
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(as_handle<XrSession>(t->session), s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_HAND_JOINTS_LOCATE_INFO_EXT) return XR_ERROR_VALIDATION_FAILURE;
        if (!locations || locations->type != XR_TYPE_HAND_JOINT_LOCATIONS_EXT) return XR_ERROR_VALIDATION_FAILURE;
        if (locations->jointCount != XR_HAND_JOINT_COUNT_EXT || !locations->jointLocations) return XR_ERROR_VALIDATION_FAILURE;
        auto* velocities = static_cast<XrHandJointVelocitiesEXT*>(
            find_in_chain_mut(locations->next, XR_TYPE_HAND_JOINT_VELOCITIES_EXT));
        if (velocities && (velocities->jointCount != XR_HAND_JOINT_COUNT_EXT || !velocities->jointVelocities))
            return XR_ERROR_VALIDATION_FAILURE;
        const Space* base = find<Space>(key(info->baseSpace), Kind::Space);
        if (!base || base->session != s->handle) return XR_ERROR_HANDLE_INVALID;
        if (validate_time(info->time) != XR_SUCCESS) return XR_ERROR_TIME_INVALID;

        const std::size_t f = frame_at(*inst, info->time);
        const int h = t->hand == XR_HAND_LEFT_EXT ? 0 : 1;
        const HandState& hand = inst->recording.frames[f].hands[h];
        const Located b = locate_in_stage(*inst, *base, info->time);
        constexpr XrSpaceLocationFlags kValid = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT;
        const bool active = hand.active && (b.flags & kValid) == kValid;
        locations->isActive = active ? XR_TRUE : XR_FALSE;
        const RigidPose to_base = inverse(b.pose);
        // Tracked bits survive only where the base space is tracked too.
        const XrSpaceLocationFlags keep = kValid | (b.flags & ~kValid);
        const HandState* prev = f > 0 ? &inst->recording.frames[f - 1].hands[h] : nullptr;
        const double dt = f > 0 ? inst->recording.frames[f].time - inst->recording.frames[f - 1].time : 0.0;
        for (std::uint32_t j = 0; j < XR_HAND_JOINT_COUNT_EXT; ++j) {
            XrHandJointLocationEXT& out = locations->jointLocations[j];
            const JointState& js = hand.joints[j];
            if (!active) {
                out = XrHandJointLocationEXT{0, XrPosef{{0, 0, 0, 1}, {0, 0, 0}}, 0.0f};
            } else {
                out.locationFlags = static_cast<XrSpaceLocationFlags>(js.flags & kAllJointFlags) & keep;
                out.pose = to_xr(compose(to_base, joint_pose(js)));
                out.radius = js.radius;
            }
            if (!velocities) continue;
            XrHandJointVelocityEXT& v = velocities->jointVelocities[j];
            v = XrHandJointVelocityEXT{0, {0, 0, 0}, {0, 0, 0}};
            // Linear velocity from the previous recorded frame, when both positions are known.
            if (active && prev && prev->active && dt > 0.0 && js.position_valid() && prev->joints[j].position_valid()) {
                RigidPose d;
                const auto& a = prev->joints[j].pose.position;
                const auto& c = js.pose.position;
                d.position = {static_cast<float>((c.x - a.x) / dt), static_cast<float>((c.y - a.y) / dt),
                              static_cast<float>((c.z - a.z) / dt)};
                RigidPose rot_only = to_base;
                rot_only.position = {0, 0, 0};
                v.linearVelocity = compose(rot_only, d).position;
                v.velocityFlags = XR_SPACE_VELOCITY_LINEAR_VALID_BIT;
            }
        }
        return XR_SUCCESS;
    });
}

} // namespace lobe::xrr
