// The action system with no controllers present: everything is validated as a real runtime
// would, bindings are accepted, and every action stays inactive (no source is ever bound).

#include <algorithm>
#include <cstring>
#include <string_view>

#include "input/openxr_replay/runtime.h"

namespace lobe::xrr {
namespace {

/// Action and action set names: lower-case letters, digits, '-', '_', '.'; not empty.
bool well_formed_name(const char* s, std::size_t max)
{
    const std::size_t n = strnlen(s, max);
    if (n == 0 || n == max) return false;
    for (std::size_t i = 0; i < n; ++i) {
        const char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.')) return false;
    }
    return true;
}

bool localized_name_ok(const char* s, std::size_t max)
{
    const std::size_t n = strnlen(s, max);
    return n > 0 && n < max;
}

const char* const kProfiles[] = {
    "/interaction_profiles/khr/simple_controller",
    "/interaction_profiles/google/daydream_controller",
    "/interaction_profiles/htc/vive_controller",
    "/interaction_profiles/htc/vive_pro",
    "/interaction_profiles/microsoft/motion_controller",
    "/interaction_profiles/microsoft/xbox_controller",
    "/interaction_profiles/oculus/go_controller",
    "/interaction_profiles/oculus/touch_controller",
    "/interaction_profiles/valve/index_controller",
    "/interaction_profiles/htc/vive_cosmos_controller",
    "/interaction_profiles/htc/vive_focus3_controller",
    "/interaction_profiles/hp/mixed_reality_controller",
    "/interaction_profiles/samsung/odyssey_controller",
    "/interaction_profiles/ext/hand_interaction_ext",
    "/interaction_profiles/microsoft/hand_interaction",
    "/interaction_profiles/ext/eye_gaze_interaction",
    "/interaction_profiles/huawei/controller",
};

bool known_profile(const std::string& p)
{
    return std::find(std::begin(kProfiles), std::end(kProfiles), p) != std::end(kProfiles);
}

/// Finds the action of a get-state call and checks what every such call checks.
XrResult state_checks(XrSession session, const XrActionStateGetInfo* info, XrActionType want, bool pose_ok,
                      Session*& s, Instance*& inst, Action*& action)
{
    XrResult r;
    if (!session_checks(session, s, inst, r)) return r;
    if (!info || info->type != XR_TYPE_ACTION_STATE_GET_INFO) return XR_ERROR_VALIDATION_FAILURE;
    action = find<Action>(key(info->action), Kind::Action);
    if (!action) return XR_ERROR_HANDLE_INVALID;
    const ActionSet* set = find<ActionSet>(action->parent, Kind::ActionSet);
    if (!set || std::find(s->attached_action_sets.begin(), s->attached_action_sets.end(), set->handle) ==
                    s->attached_action_sets.end())
        return XR_ERROR_ACTIONSET_NOT_ATTACHED;
    const bool type_ok = action->type == want || (pose_ok && action->type == XR_ACTION_TYPE_POSE_INPUT);
    if (!type_ok) return XR_ERROR_ACTION_TYPE_MISMATCH;
    if (info->subactionPath != XR_NULL_PATH) {
        if (path_string(*inst, info->subactionPath).empty()) return XR_ERROR_PATH_INVALID;
        if (std::find(action->subactions.begin(), action->subactions.end(), info->subactionPath) == action->subactions.end())
            return XR_ERROR_PATH_UNSUPPORTED;
    }
    return XR_SUCCESS;
}

} // namespace

XrResult XRAPI_CALL xrCreateActionSet(XrInstance instance, const XrActionSetCreateInfo* info, XrActionSet* out)
{
    return guarded("xrCreateActionSet", [&]() -> XrResult {
        Instance* inst = find<Instance>(key(instance), Kind::Instance);
        if (!inst) return XR_ERROR_HANDLE_INVALID;
        if (!info || !out || info->type != XR_TYPE_ACTION_SET_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (!well_formed_name(info->actionSetName, XR_MAX_ACTION_SET_NAME_SIZE)) return XR_ERROR_PATH_FORMAT_INVALID;
        if (!localized_name_ok(info->localizedActionSetName, XR_MAX_LOCALIZED_ACTION_SET_NAME_SIZE))
            return XR_ERROR_LOCALIZED_NAME_INVALID;
        for (std::uint64_t h : children_of(inst->handle, Kind::ActionSet)) {
            const auto* other = find<ActionSet>(h, Kind::ActionSet);
            if (other->name == info->actionSetName) return XR_ERROR_NAME_DUPLICATED;
            if (other->localized_name == info->localizedActionSetName) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
        }
        auto set = std::make_unique<ActionSet>();
        set->name = info->actionSetName;
        set->localized_name = info->localizedActionSetName;
        set->priority = info->priority;
        *out = as_handle<XrActionSet>(add_object(std::move(set), inst->handle));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroyActionSet(XrActionSet action_set)
{
    return guarded("xrDestroyActionSet", [&]() -> XrResult {
        ActionSet* set = find<ActionSet>(key(action_set), Kind::ActionSet);
        if (!set) return XR_ERROR_HANDLE_INVALID;
        // An attached set stays usable by its session until the session ends (we keep
        // nothing from it that the session needs), so it can go at once.
        destroy_object(set->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrCreateAction(XrActionSet action_set, const XrActionCreateInfo* info, XrAction* out)
{
    return guarded("xrCreateAction", [&]() -> XrResult {
        ActionSet* set = find<ActionSet>(key(action_set), Kind::ActionSet);
        if (!set) return XR_ERROR_HANDLE_INVALID;
        Instance* inst = find<Instance>(set->parent, Kind::Instance);
        if (!inst) return XR_ERROR_HANDLE_INVALID;
        if (!info || !out || info->type != XR_TYPE_ACTION_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (set->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
        if (!well_formed_name(info->actionName, XR_MAX_ACTION_NAME_SIZE)) return XR_ERROR_PATH_FORMAT_INVALID;
        if (!localized_name_ok(info->localizedActionName, XR_MAX_LOCALIZED_ACTION_NAME_SIZE))
            return XR_ERROR_LOCALIZED_NAME_INVALID;
        switch (info->actionType) {
        case XR_ACTION_TYPE_BOOLEAN_INPUT:
        case XR_ACTION_TYPE_FLOAT_INPUT:
        case XR_ACTION_TYPE_VECTOR2F_INPUT:
        case XR_ACTION_TYPE_POSE_INPUT:
        case XR_ACTION_TYPE_VIBRATION_OUTPUT: break;
        default: return XR_ERROR_VALIDATION_FAILURE;
        }
        for (std::uint64_t h : children_of(set->handle, Kind::Action)) {
            const auto* other = find<Action>(h, Kind::Action);
            if (other->name == info->actionName) return XR_ERROR_NAME_DUPLICATED;
            if (other->localized_name == info->localizedActionName) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
        }
        if (info->countSubactionPaths > 0 && !info->subactionPaths) return XR_ERROR_VALIDATION_FAILURE;
        auto action = std::make_unique<Action>();
        for (std::uint32_t i = 0; i < info->countSubactionPaths; ++i) {
            const XrPath p = info->subactionPaths[i];
            const std::string ps = path_string(*inst, p);
            if (ps.empty()) return XR_ERROR_PATH_INVALID;
            if (!top_level_user_path(ps)) return XR_ERROR_PATH_UNSUPPORTED;
            if (std::find(action->subactions.begin(), action->subactions.end(), p) != action->subactions.end())
                return XR_ERROR_PATH_UNSUPPORTED;
            action->subactions.push_back(p);
        }
        action->name = info->actionName;
        action->localized_name = info->localizedActionName;
        action->type = info->actionType;
        *out = as_handle<XrAction>(add_object(std::move(action), set->handle));
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrDestroyAction(XrAction action)
{
    return guarded("xrDestroyAction", [&]() -> XrResult {
        Action* a = find<Action>(key(action), Kind::Action);
        if (!a) return XR_ERROR_HANDLE_INVALID;
        destroy_object(a->handle);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrSuggestInteractionProfileBindings(XrInstance instance, const XrInteractionProfileSuggestedBinding* info)
{
    return guarded("xrSuggestInteractionProfileBindings", [&]() -> XrResult {
        Instance* inst = find<Instance>(key(instance), Kind::Instance);
        if (!inst) return XR_ERROR_HANDLE_INVALID;
        if (!info || info->type != XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING) return XR_ERROR_VALIDATION_FAILURE;
        if (info->countSuggestedBindings == 0 || !info->suggestedBindings) return XR_ERROR_VALIDATION_FAILURE;
        const std::string profile = path_string(*inst, info->interactionProfile);
        if (profile.empty()) return XR_ERROR_PATH_INVALID;
        if (!known_profile(profile)) return XR_ERROR_PATH_UNSUPPORTED;
        for (std::uint32_t i = 0; i < info->countSuggestedBindings; ++i) {
            const XrActionSuggestedBinding& b = info->suggestedBindings[i];
            const Action* a = find<Action>(key(b.action), Kind::Action);
            if (!a) return XR_ERROR_HANDLE_INVALID;
            const ActionSet* set = find<ActionSet>(a->parent, Kind::ActionSet);
            if (!set || set->parent != inst->handle) return XR_ERROR_HANDLE_INVALID;
            if (set->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
            const std::string binding = path_string(*inst, b.binding);
            if (binding.empty()) return XR_ERROR_PATH_INVALID;
            if (binding.rfind("/user/", 0) != 0) return XR_ERROR_PATH_UNSUPPORTED;
        }
        return XR_SUCCESS; // accepted; no controller will ever use it
    });
}

XrResult XRAPI_CALL xrAttachSessionActionSets(XrSession session, const XrSessionActionSetsAttachInfo* info)
{
    return guarded("xrAttachSessionActionSets", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (info->countActionSets == 0 || !info->actionSets) return XR_ERROR_VALIDATION_FAILURE;
        if (!s->attached_action_sets.empty()) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
        std::vector<std::uint64_t> sets;
        for (std::uint32_t i = 0; i < info->countActionSets; ++i) {
            ActionSet* set = find<ActionSet>(key(info->actionSets[i]), Kind::ActionSet);
            if (!set || set->parent != inst->handle) return XR_ERROR_HANDLE_INVALID;
            sets.push_back(set->handle);
        }
        for (std::uint64_t h : sets) find<ActionSet>(h, Kind::ActionSet)->attached = true;
        s->attached_action_sets = std::move(sets);
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetCurrentInteractionProfile(XrSession session, XrPath top_level, XrInteractionProfileState* state)
{
    return guarded("xrGetCurrentInteractionProfile", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!state || state->type != XR_TYPE_INTERACTION_PROFILE_STATE) return XR_ERROR_VALIDATION_FAILURE;
        const std::string p = path_string(*inst, top_level);
        if (p.empty()) return XR_ERROR_PATH_INVALID;
        if (!top_level_user_path(p)) return XR_ERROR_PATH_UNSUPPORTED;
        if (s->attached_action_sets.empty()) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
        state->interactionProfile = XR_NULL_PATH; // no controller is connected
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetActionStateBoolean(XrSession session, const XrActionStateGetInfo* info, XrActionStateBoolean* state)
{
    return guarded("xrGetActionStateBoolean", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (XrResult r = state_checks(session, info, XR_ACTION_TYPE_BOOLEAN_INPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        if (!state || state->type != XR_TYPE_ACTION_STATE_BOOLEAN) return XR_ERROR_VALIDATION_FAILURE;
        state->currentState = XR_FALSE;
        state->changedSinceLastSync = XR_FALSE;
        state->lastChangeTime = 0;
        state->isActive = XR_FALSE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetActionStateFloat(XrSession session, const XrActionStateGetInfo* info, XrActionStateFloat* state)
{
    return guarded("xrGetActionStateFloat", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (XrResult r = state_checks(session, info, XR_ACTION_TYPE_FLOAT_INPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        if (!state || state->type != XR_TYPE_ACTION_STATE_FLOAT) return XR_ERROR_VALIDATION_FAILURE;
        state->currentState = 0.0f;
        state->changedSinceLastSync = XR_FALSE;
        state->lastChangeTime = 0;
        state->isActive = XR_FALSE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetActionStateVector2f(XrSession session, const XrActionStateGetInfo* info, XrActionStateVector2f* state)
{
    return guarded("xrGetActionStateVector2f", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (XrResult r = state_checks(session, info, XR_ACTION_TYPE_VECTOR2F_INPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        if (!state || state->type != XR_TYPE_ACTION_STATE_VECTOR2F) return XR_ERROR_VALIDATION_FAILURE;
        state->currentState = {0.0f, 0.0f};
        state->changedSinceLastSync = XR_FALSE;
        state->lastChangeTime = 0;
        state->isActive = XR_FALSE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrGetActionStatePose(XrSession session, const XrActionStateGetInfo* info, XrActionStatePose* state)
{
    return guarded("xrGetActionStatePose", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (XrResult r = state_checks(session, info, XR_ACTION_TYPE_POSE_INPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        if (!state || state->type != XR_TYPE_ACTION_STATE_POSE) return XR_ERROR_VALIDATION_FAILURE;
        state->isActive = XR_FALSE;
        return XR_SUCCESS;
    });
}

XrResult XRAPI_CALL xrSyncActions(XrSession session, const XrActionsSyncInfo* info)
{
    return guarded("xrSyncActions", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_ACTIONS_SYNC_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (info->countActiveActionSets > 0 && !info->activeActionSets) return XR_ERROR_VALIDATION_FAILURE;
        for (std::uint32_t i = 0; i < info->countActiveActionSets; ++i) {
            const XrActiveActionSet& as = info->activeActionSets[i];
            const ActionSet* set = find<ActionSet>(key(as.actionSet), Kind::ActionSet);
            if (!set) return XR_ERROR_HANDLE_INVALID;
            if (std::find(s->attached_action_sets.begin(), s->attached_action_sets.end(), set->handle) ==
                s->attached_action_sets.end())
                return XR_ERROR_ACTIONSET_NOT_ATTACHED;
            if (as.subactionPath != XR_NULL_PATH) {
                const std::string p = path_string(*inst, as.subactionPath);
                if (p.empty()) return XR_ERROR_PATH_INVALID;
                if (!top_level_user_path(p)) return XR_ERROR_PATH_UNSUPPORTED;
            }
        }
        return s->state == XR_SESSION_STATE_FOCUSED ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
    });
}

XrResult XRAPI_CALL xrEnumerateBoundSourcesForAction(XrSession session, const XrBoundSourcesForActionEnumerateInfo* info,
                                                     uint32_t capacity, uint32_t* count, XrPath* sources)
{
    return guarded("xrEnumerateBoundSourcesForAction", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        const Action* a = find<Action>(key(info->action), Kind::Action);
        if (!a) return XR_ERROR_HANDLE_INVALID;
        if (std::find(s->attached_action_sets.begin(), s->attached_action_sets.end(), a->parent) ==
            s->attached_action_sets.end())
            return XR_ERROR_ACTIONSET_NOT_ATTACHED;
        return enumerate(std::vector<XrPath>{}, capacity, count, sources);
    });
}

XrResult XRAPI_CALL xrGetInputSourceLocalizedName(XrSession session, const XrInputSourceLocalizedNameGetInfo* info,
                                                  uint32_t capacity, uint32_t* count, char* buffer)
{
    return guarded("xrGetInputSourceLocalizedName", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || info->type != XR_TYPE_INPUT_SOURCE_LOCALIZED_NAME_GET_INFO) return XR_ERROR_VALIDATION_FAILURE;
        if (info->whichComponents == 0) return XR_ERROR_VALIDATION_FAILURE;
        if (s->attached_action_sets.empty()) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
        if (path_string(*inst, info->sourcePath).empty()) return XR_ERROR_PATH_INVALID;
        (void)capacity;
        (void)count;
        (void)buffer;
        return XR_ERROR_PATH_UNSUPPORTED; // no source is bound, so no path names one
    });
}

XrResult XRAPI_CALL xrApplyHapticFeedback(XrSession session, const XrHapticActionInfo* info, const XrHapticBaseHeader* haptic)
{
    return guarded("xrApplyHapticFeedback", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (!info || info->type != XR_TYPE_HAPTIC_ACTION_INFO || !haptic) return XR_ERROR_VALIDATION_FAILURE;
        if (haptic->type != XR_TYPE_HAPTIC_VIBRATION) return XR_ERROR_VALIDATION_FAILURE;
        XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO, nullptr, info->action, info->subactionPath};
        if (XrResult r = state_checks(session, &get, XR_ACTION_TYPE_VIBRATION_OUTPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        return s->state == XR_SESSION_STATE_FOCUSED ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
    });
}

XrResult XRAPI_CALL xrStopHapticFeedback(XrSession session, const XrHapticActionInfo* info)
{
    return guarded("xrStopHapticFeedback", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        Action* a;
        if (!info || info->type != XR_TYPE_HAPTIC_ACTION_INFO) return XR_ERROR_VALIDATION_FAILURE;
        XrActionStateGetInfo get{XR_TYPE_ACTION_STATE_GET_INFO, nullptr, info->action, info->subactionPath};
        if (XrResult r = state_checks(session, &get, XR_ACTION_TYPE_VIBRATION_OUTPUT, false, s, inst, a); r != XR_SUCCESS) return r;
        return s->state == XR_SESSION_STATE_FOCUSED ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
    });
}

XrResult XRAPI_CALL xrCreateActionSpace(XrSession session, const XrActionSpaceCreateInfo* info, XrSpace* out)
{
    return guarded("xrCreateActionSpace", [&]() -> XrResult {
        Session* s;
        Instance* inst;
        XrResult r;
        if (!session_checks(session, s, inst, r)) return r;
        if (!info || !out || info->type != XR_TYPE_ACTION_SPACE_CREATE_INFO) return XR_ERROR_VALIDATION_FAILURE;
        const Action* a = find<Action>(key(info->action), Kind::Action);
        if (!a) return XR_ERROR_HANDLE_INVALID;
        if (a->type != XR_ACTION_TYPE_POSE_INPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
        if (info->subactionPath != XR_NULL_PATH) {
            if (path_string(*inst, info->subactionPath).empty()) return XR_ERROR_PATH_INVALID;
            if (std::find(a->subactions.begin(), a->subactions.end(), info->subactionPath) == a->subactions.end())
                return XR_ERROR_PATH_UNSUPPORTED;
        }
        if (!pose_valid(info->poseInActionSpace)) return XR_ERROR_POSE_INVALID;
        auto sp = std::make_unique<Space>();
        sp->session = s->handle;
        sp->action = a->handle;
        sp->subaction = info->subactionPath;
        sp->offset = to_rigid(info->poseInActionSpace);
        *out = as_handle<XrSpace>(add_object(std::move(sp), s->handle));
        return XR_SUCCESS;
    });
}

} // namespace lobe::xrr
