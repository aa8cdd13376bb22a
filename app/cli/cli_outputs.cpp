#include "app/cli/outputs.h"

#include <algorithm>
#include <cctype>
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
    std::vector<std::string> names;
    for (LobeRecord& rec : doc.lobes) {
        rec.mesh_file.clear();
        for (const BuiltLobe& b : lobes) {
            if (b.lobe_id != rec.id) continue;
            const std::string name = "lobes/lobe_" + std::to_string(rec.id) + ".ply";
            write_ply(out_dir + "/" + name, b.mesh);
            rec.mesh_file = name;
            names.push_back(std::filesystem::path(name).filename().string());
            ++written;
        }
    }
    if (const std::size_t removed = remove_stale_lobe_files(dir, names); removed > 0)
        warnings.push_back("removed " + std::to_string(removed) + " lobe mesh(es) of an earlier run from " + dir);
    if (built) *built = std::move(lobes);
    return written;
}

std::size_t remove_stale_lobe_files(const std::string& lobes_dir, const std::vector<std::string>& kept)
{
    std::error_code ec;
    std::vector<std::filesystem::path> stale;
    for (std::filesystem::directory_iterator it(lobes_dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() <= 9 || name.rfind("lobe_", 0) != 0 || !name.ends_with(".ply")) continue;
        const std::string digits = name.substr(5, name.size() - 9);
        if (!std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) continue;
        if (std::find(kept.begin(), kept.end(), name) == kept.end()) stale.push_back(it->path());
    }
    for (const std::filesystem::path& p : stale) {
        std::filesystem::remove(p, ec);
        if (ec) throw FileError(p.string(), "cannot remove this lobe mesh of an earlier run: " + ec.message());
    }
    return stale.size();
}

} // namespace lobe
