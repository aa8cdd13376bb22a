#include "app/outputs.h"

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"

namespace lobe {

void write_strokes_json(const std::string& path, const std::vector<Stroke>& strokes, const std::string& source)
{
    nlohmann::json arr = nlohmann::json::array();
    for (const Stroke& s : strokes) {
        nlohmann::json pts = nlohmann::json::array();
        nlohmann::json times = nlohmann::json::array();
        for (const StrokePoint& p : s.points) {
            pts.push_back({p.position.x, p.position.y, p.position.z});
            times.push_back(p.time);
        }
        arr.push_back({{"id", s.id},
                       {"kind", stroke_kind_name(s.kind)},
                       {"closed", s.closed},
                       {"hand", hand_name(s.hand)},
                       {"points", std::move(pts)},
                       {"times", std::move(times)}});
    }
    nlohmann::json j = {{"format", "lobesketch-strokes"}, {"version", 1}, {"source", source}, {"strokes", std::move(arr)}};
    write_file_atomic(path, j.dump(1) + "\n");
}

} // namespace lobe
