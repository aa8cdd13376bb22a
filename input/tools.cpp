#include "input/tools.h"

namespace lobe {

const char* tool_name(Tool t)
{
    switch (t) {
    case Tool::DrawLobe: return "draw-lobe";
    case Tool::DrawTrunk: return "draw-trunk";
    case Tool::DeformLobe: return "deform-lobe";
    case Tool::EditStroke: return "edit-stroke";
    case Tool::MoveLobe: return "move-lobe";
    case Tool::RotateLobe: return "rotate-lobe";
    case Tool::ScaleLobe: return "scale-lobe";
    }
    return "unknown";
}

} // namespace lobe
