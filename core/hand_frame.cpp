#include "core/hand_frame.h"

namespace lobe {

const char* joint_name(Joint j)
{
    static constexpr const char* names[kJointCount] = {
        "palm", "wrist",
        "thumb_metacarpal", "thumb_proximal", "thumb_distal", "thumb_tip",
        "index_metacarpal", "index_proximal", "index_intermediate", "index_distal", "index_tip",
        "middle_metacarpal", "middle_proximal", "middle_intermediate", "middle_distal", "middle_tip",
        "ring_metacarpal", "ring_proximal", "ring_intermediate", "ring_distal", "ring_tip",
        "little_metacarpal", "little_proximal", "little_intermediate", "little_distal", "little_tip",
    };
    int i = idx(j);
    return (i >= 0 && i < kJointCount) ? names[i] : "invalid";
}

const char* hand_name(Hand h) { return h == Hand::Left ? "left" : "right"; }

} // namespace lobe
