#include "input/hand_model.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace lobe::hand_model {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float deg(float d) { return d * kPi / 180.0f; }

/// Largest flexion (curl = 1) of the MCP, PIP and DIP joints.
constexpr float kMcpMax = deg(90.0f);
constexpr float kPipMax = deg(105.0f);
constexpr float kDipMax = deg(75.0f);

/// Thumb bend per unit of the reach parameter: the metacarpal keeps the chord-relative angle,
/// the MCP takes 45 % and the IP joint 55 % of the bend.
constexpr float kThumbMcpShare = 0.45f;
constexpr float kThumbMaxBend = 2.6f; ///< radians, total

/// Orientation whose -Z is `along` and +Y is `up` made perpendicular to it.
glm::quat frame(const glm::vec3& along, const glm::vec3& up)
{
    glm::vec3 z = -glm::normalize(along);
    glm::vec3 y = up - glm::dot(up, z) * z;
    float len = glm::length(y);
    if (len < 1e-6f) {
        // `up` along the bone: any perpendicular will do.
        glm::vec3 any = std::abs(z.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
        y = glm::normalize(any - glm::dot(any, z) * z);
    } else {
        y /= len;
    }
    glm::vec3 x = glm::cross(y, z);
    return glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
}

/// End of a planar chain with cumulative bend angles phi_i = w_i · c, in (along, towards) coordinates.
glm::vec2 chain_end(const std::array<float, 3>& len, const std::array<float, 3>& phi)
{
    glm::vec2 e(0.0f);
    for (int i = 0; i < 3; ++i) e += len[i] * glm::vec2(std::cos(phi[i]), std::sin(phi[i]));
    return e;
}

std::array<float, 3> thumb_angles(float c) { return {0.0f, kThumbMcpShare * c, c}; }

} // namespace

HandShape make_hand_shape(float scale, float uniform_radius)
{
    HandShape s;
    s.scale = scale;
    const float mm = 0.001f * scale;
    // Wrist frame of a relaxed right hand, Meta Quest 3 capture (see the file comment).
    s.metacarpal_base = {glm::vec3(-29.0f, -17.0f, -35.0f), glm::vec3(-19.0f, -10.0f, -37.0f),
                         glm::vec3(-2.0f, -8.0f, -35.0f), glm::vec3(15.0f, -6.0f, -35.0f),
                         glm::vec3(22.7f, -9.0f, -34.0f)};
    s.knuckle = {glm::vec3(0.0f), glm::vec3(-23.5f, -7.5f, -95.5f), glm::vec3(-1.6f, -2.3f, -95.6f),
                 glm::vec3(17.4f, -6.6f, -88.3f), glm::vec3(35.0f, -13.4f, -78.0f)};
    for (auto& p : s.metacarpal_base) p *= mm;
    for (auto& p : s.knuckle) p *= mm;
    // Phalanges (mm): Quest 3 index 38/24/22, middle 43/27/25, ring 39/26/24, little 31/20/22,
    // thumb 33/34/25; the index is nudged towards the textbook 40/23/18.
    s.bones = {{{33.0f, 34.0f, 26.0f}, {39.0f, 24.0f, 20.0f}, {43.0f, 27.0f, 24.0f},
                {39.0f, 26.0f, 23.0f}, {31.0f, 20.0f, 21.0f}}};
    for (auto& b : s.bones)
        for (auto& l : b) l *= mm;
    // Radii (mm): Quest 3 per-joint radii; tips 8–9 mm as the Leap's ~19 mm wide fingers.
    static constexpr float radius_mm[kJointCount] = {
        20.0f, 21.0f,                     // palm, wrist
        19.0f, 12.0f, 10.0f, 9.0f,        // thumb
        21.0f, 10.0f, 9.0f, 8.0f, 8.0f,   // index
        21.0f, 11.0f, 8.5f, 8.0f, 8.0f,   // middle
        19.0f, 10.0f, 8.0f, 7.0f, 7.0f,   // ring
        18.0f, 8.0f, 7.0f, 6.0f, 6.0f,    // little
    };
    for (int j = 0; j < kJointCount; ++j)
        s.radius[j] = uniform_radius > 0.0f ? uniform_radius : radius_mm[j] * mm;
    return s;
}

void pose_fingers(const HandShape& shape, const Articulation& art, LocalHand& out)
{
    const glm::vec3 hand_up(0.0f, 1.0f, 0.0f);
    out[idx(Joint::Wrist)] = {glm::vec3(0.0f), glm::quat(1.0f, 0.0f, 0.0f, 0.0f)};
    for (int f = kIndex; f <= kLittle; ++f) {
        const int j0 = idx(Joint::IndexMetacarpal) + 5 * (f - kIndex);
        const glm::vec3 base = shape.metacarpal_base[f];
        const glm::vec3 knuckle = shape.knuckle[f];
        const glm::vec3 m = glm::normalize(knuckle - base);
        const glm::vec3 ym = glm::normalize(hand_up - glm::dot(hand_up, m) * m);
        out[j0] = {base, frame(m, ym)};

        const float c = std::clamp(art.curl[f], 0.0f, 1.2f);
        // Abduction about the metacarpal's dorsal axis; fingers close up as they curl.
        const float side = f == kIndex ? -1.0f : 1.0f;
        const float a = side * art.spread[f] * (1.0f - 0.7f * std::min(c, 1.0f));
        const glm::vec3 lateral = glm::normalize(glm::cross(m, ym)); // towards the little finger
        const glm::vec3 f0 = std::cos(a) * m + std::sin(a) * lateral;
        const glm::vec3 p0 = -ym; // palmar
        const std::array<float, 3> phi = {kMcpMax * c, (kMcpMax + kPipMax) * c,
                                          (kMcpMax + kPipMax + kDipMax) * c};
        glm::vec3 p = knuckle;
        for (int b = 0; b < 3; ++b) {
            const glm::vec3 dir = std::cos(phi[b]) * f0 + std::sin(phi[b]) * p0;
            const glm::vec3 up = std::sin(phi[b]) * f0 - std::cos(phi[b]) * p0;
            const glm::quat q = frame(dir, up);
            out[j0 + 1 + b] = {p, q};
            p += shape.bones[f][b] * dir;
            if (b == 2) out[j0 + 4] = {p, q};
        }
    }
    // OpenXR: the palm is the centre of the middle metacarpal, oriented like it.
    const int mid = idx(Joint::MiddleMetacarpal);
    out[idx(Joint::Palm)] = {0.5f * (out[mid].position + out[mid + 1].position), out[mid].orientation};
}

float pose_thumb(const HandShape& shape, const glm::vec3& tip_target, LocalHand& out)
{
    const glm::vec3 base = shape.metacarpal_base[kThumb];
    const std::array<float, 3>& len = shape.bones[kThumb];
    glm::vec3 chord = tip_target - base;
    float dist = glm::length(chord);
    glm::vec3 d = dist > 1e-6f ? chord / dist : glm::vec3(-0.6f, -0.3f, -0.74f);

    // Reach decreases monotonically with the bend: bisect for the wanted distance.
    float lo = 0.0f, hi = kThumbMaxBend;
    float c = 0.0f;
    if (dist >= glm::length(chain_end(len, thumb_angles(0.0f)))) {
        c = 0.0f;
    } else if (dist <= glm::length(chain_end(len, thumb_angles(kThumbMaxBend)))) {
        c = kThumbMaxBend;
    } else {
        for (int it = 0; it < 40; ++it) {
            float mid = 0.5f * (lo + hi);
            if (glm::length(chain_end(len, thumb_angles(mid))) > dist) lo = mid;
            else hi = mid;
        }
        c = 0.5f * (lo + hi);
    }
    const std::array<float, 3> phi = thumb_angles(c);
    const glm::vec2 e = chain_end(len, phi);

    // The bend faces the palm (towards the little finger side and palmar).
    const glm::vec3 hint = glm::normalize(glm::vec3(0.75f, -0.45f, -0.35f));
    glm::vec3 towards = hint - glm::dot(hint, d) * d;
    if (glm::length(towards) < 1e-4f) towards = glm::vec3(0.0f, -1.0f, 0.0f) - d.y * d;
    towards = glm::normalize(towards);
    const float alpha = std::atan2(e.y, e.x);
    const glm::vec3 e1 = std::cos(alpha) * d - std::sin(alpha) * towards;
    const glm::vec3 e2 = std::sin(alpha) * d + std::cos(alpha) * towards;

    glm::vec3 p = base;
    const int j0 = idx(Joint::ThumbMetacarpal);
    for (int b = 0; b < 3; ++b) {
        const glm::vec3 dir = std::cos(phi[b]) * e1 + std::sin(phi[b]) * e2;
        const glm::vec3 up = std::sin(phi[b]) * e1 - std::cos(phi[b]) * e2; // the nail side
        const glm::quat q = frame(dir, up);
        out[j0 + b] = {p, q};
        p += len[b] * dir;
        if (b == 2) out[j0 + 3] = {p, q};
    }
    return glm::length(p - tip_target);
}

glm::vec3 mirror(const glm::vec3& p, Hand hand)
{
    return hand == Hand::Right ? p : glm::vec3(-p.x, p.y, p.z);
}

glm::quat mirror(const glm::quat& q, Hand hand)
{
    // Reflection x → -x conjugating a rotation: the rotation axis is a pseudovector.
    return hand == Hand::Right ? q : glm::quat(q.w, q.x, -q.y, -q.z);
}

HandState place_hand(const HandShape& shape, const LocalHand& local, Hand hand,
                     const glm::quat& rotation, const glm::vec3& translation)
{
    HandState hs;
    hs.active = true;
    for (int j = 0; j < kJointCount; ++j) {
        JointState& js = hs.joints[j];
        js.pose.position = translation + rotation * mirror(local[j].position, hand);
        js.pose.orientation = glm::normalize(rotation * mirror(local[j].orientation, hand));
        js.radius = shape.radius[j];
        js.flags = kAllJointFlags;
    }
    return hs;
}

} // namespace lobe::hand_model
