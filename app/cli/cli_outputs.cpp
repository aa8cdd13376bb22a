#include "app/cli/outputs.h"

#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "app/session/lobe_document.h"
#include "meshing/mesh_io.h"

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

namespace lobe {

std::size_t write_document_lobes(Document& doc, const std::string& out_dir, std::vector<std::string>& warnings,
                                 std::vector<BuiltLobe>* built)
{
    std::vector<BuiltLobe> lobes = build_document_lobes(doc, &warnings);
    const std::string dir = out_dir + "/lobes";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw FileError(dir, "cannot create folder: " + ec.message());
    std::size_t written = 0;
    for (LobeRecord& rec : doc.lobes) {
        rec.mesh_file.clear();
        for (const BuiltLobe& b : lobes) {
            if (b.lobe_id != rec.id) continue;
            const std::string name = "lobes/lobe_" + std::to_string(rec.id) + ".ply";
            write_ply(out_dir + "/" + name, b.mesh);
            rec.mesh_file = name;
            ++written;
        }
    }
    if (built) *built = std::move(lobes);
    return written;
}

} // namespace lobe
