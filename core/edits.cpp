#include "core/edits.h"

#include <array>
#include <cmath>
#include <type_traits>

#include "core/stroke.h"

namespace lobe {

namespace {

struct KindName {
    EditKind kind;
    const char* name;
};

// The names are a file-format contract (docs/session-format.md): never change one.
constexpr std::array<KindName, 5> kKindNames{{
    {EditKind::DeformLobe, "drag:deform-lobe"},
    {EditKind::EditStroke, "drag:edit-stroke"},
    {EditKind::MoveLobe, "drag:move-lobe"},
    {EditKind::RotateLobe, "drag:rotate-lobe"},
    {EditKind::ScaleLobe, "drag:scale-lobe"},
}};

template <EditKind K, typename P>
constexpr bool holds_at = std::is_same_v<std::variant_alternative_t<static_cast<std::size_t>(K), EditParams>, P>;
static_assert(holds_at<EditKind::DeformLobe, DeformLobeParams> && holds_at<EditKind::EditStroke, EditStrokeParams> &&
                  holds_at<EditKind::MoveLobe, MoveLobeParams> && holds_at<EditKind::RotateLobe, RotateLobeParams> &&
                  holds_at<EditKind::ScaleLobe, ScaleLobeParams> && std::variant_size_v<EditParams> == 5,
              "EditParams holds one alternative per EditKind, in EditKind order");

/// Empty when every coordinate of `p` is finite and within kMaxStrokeCoordinateM.
std::string coordinate_problem(const glm::dvec3& p)
{
    for (int k = 0; k < 3; ++k)
        if (!(std::abs(p[k]) <= kMaxStrokeCoordinateM)) return "a coordinate is not finite or beyond 1 km";
    return {};
}

std::string length_problem(const std::optional<double>& v)
{
    if (v && !(std::isfinite(*v) && *v > 0.0)) return "expected a positive number";
    return {};
}

} // namespace

const char* edit_kind_name(EditKind kind)
{
    for (const KindName& k : kKindNames)
        if (k.kind == kind) return k.name;
    return "drag:unknown";
}

std::optional<EditKind> edit_kind_from_name(std::string_view name)
{
    for (const KindName& k : kKindNames)
        if (name == k.name) return k.kind;
    return std::nullopt;
}

bool is_lobe_transform(EditKind kind)
{
    return kind == EditKind::MoveLobe || kind == EditKind::RotateLobe || kind == EditKind::ScaleLobe;
}

EditParams edit_params_of(EditKind kind)
{
    switch (kind) {
    case EditKind::DeformLobe: return DeformLobeParams{};
    case EditKind::EditStroke: return EditStrokeParams{};
    case EditKind::MoveLobe: return MoveLobeParams{};
    case EditKind::RotateLobe: return RotateLobeParams{};
    case EditKind::ScaleLobe: return ScaleLobeParams{};
    }
    return DeformLobeParams{};
}

namespace {

/// The move, rotate or scale parameters `params` holds (T: LobeTransformParams, const or not).
template <typename T, typename Params>
T* transform_params_in(Params& params)
{
    return std::visit(
        [](auto& p) -> T* {
            if constexpr (std::is_base_of_v<LobeTransformParams, std::remove_cvref_t<decltype(p)>>) return &p;
            else return nullptr;
        },
        params);
}

} // namespace

const LobeTransformParams* EditOperation::transform_params() const
{
    return transform_params_in<const LobeTransformParams>(params);
}

LobeTransformParams* EditOperation::transform_params() { return transform_params_in<LobeTransformParams>(params); }

std::string edit_operation_problem(const EditOperation& op)
{
    if (op.path.empty()) return "params.path: expected at least one point";
    if (op.path.size() > kMaxStrokePoints)
        return "params.path: " + std::to_string(op.path.size()) + " points, more than the " +
               std::to_string(kMaxStrokePoints) + " a path may have";
    for (std::size_t i = 0; i < op.path.size(); ++i) {
        std::string why = coordinate_problem(op.path[i].position);
        if (why.empty() && op.path[i].time && !std::isfinite(*op.path[i].time)) why = "the time is not finite";
        if (!why.empty()) return "params.path[" + std::to_string(i) + "]: " + why;
    }
    if (const EditStrokeParams* s = op.stroke_params()) {
        if (std::string why = length_problem(s->pick_distance_m); !why.empty()) return "params.pick_distance_m: " + why;
        if (std::string why = length_problem(s->half_length_m); !why.empty()) return "params.half_length_m: " + why;
        if (s->other_tip)
            if (std::string why = coordinate_problem(*s->other_tip); !why.empty()) return "params.other_tip: " + why;
    }
    if (const LobeTransformParams* t = op.transform_params()) {
        if (t->centre) {
            if (std::string why = coordinate_problem(*t->centre); !why.empty()) return "params.centre: " + why;
        } else if (op.kind() != EditKind::MoveLobe) {
            return "params.centre: missing";
        }
    }
    return {};
}

} // namespace lobe
