#include "core/stroke.h"

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace lobe {

const char* stroke_kind_name(StrokeKind k)
{
    switch (k) {
    case StrokeKind::Lobe: return "lobe";
    case StrokeKind::Trunk: return "trunk";
    }
    return "unknown";
}

StrokeKind stroke_kind_from_name(const std::string& name)
{
    if (name == "lobe") return StrokeKind::Lobe;
    if (name == "trunk") return StrokeKind::Trunk;
    throw InvalidInput("unknown stroke kind '" + name + "' (expected lobe or trunk)");
}

double Stroke::length() const
{
    double len = 0.0;
    for (std::size_t i = 1; i < points.size(); ++i)
        len += static_cast<double>(glm::distance(points[i - 1].position, points[i].position));
    return len;
}

} // namespace lobe
