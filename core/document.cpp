#include "core/document.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <unordered_set>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/settings_json.h"
#include "core/settings_table.h"

namespace lobe {

using nlohmann::json;

namespace {

/// "N LIST, more than the LIMIT a session may hold" (the document limits, docs/limits.md).
std::string too_many(std::size_t n, std::size_t limit, const char* what)
{
    return std::to_string(n) + " " + what + ", more than the " + std::to_string(limit) + " a session may hold";
}

/// A JSON number as float. A number beyond the float range becomes ±infinity (casting such a
/// double is undefined), which every caller then refuses as not finite.
float json_float(const json& v)
{
    const double d = v.get<double>();
    if (std::abs(d) <= static_cast<double>(std::numeric_limits<float>::max())) return static_cast<float>(d);
    return d < 0 ? -std::numeric_limits<float>::infinity() : std::numeric_limits<float>::infinity();
}

void check_keys(const json& obj, std::initializer_list<const char*> known, const std::string& where)
{
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool ok = false;
        for (const char* k : known) ok = ok || it.key() == k;
        if (!ok) throw InvalidInput(where + ": unknown key '" + it.key() + "'");
    }
}

void read_string(const json& obj, const char* key, std::string& out, const std::string& where)
{
    auto it = obj.find(key);
    if (it == obj.end()) return;
    if (!it->is_string()) throw InvalidInput(where + "." + key + ": expected a string");
    out = it->get<std::string>();
}

json stroke_to_json(const Stroke& s)
{
    json pts = json::array();
    for (const StrokePoint& p : s.points)
        pts.push_back(json::array({p.position.x, p.position.y, p.position.z}));
    json times = json::array();
    for (const StrokePoint& p : s.points) times.push_back(p.time);
    return json{{"id", s.id},     {"kind", stroke_kind_name(s.kind)}, {"hand", hand_name(s.hand)},
                {"closed", s.closed}, {"points", std::move(pts)},       {"times", std::move(times)}};
}

/// A lobe's override of a tree-wide setting: an optional number in the range of `setting`
/// (settings_table.h); a missing key leaves `out` empty.
void read_override(const json& obj, const char* key, const char* setting, std::optional<double>& out,
                   const std::string& where)
{
    const auto t = obj.find(key);
    if (t == obj.end()) return;
    if (!t->is_number()) throw InvalidInput(where + "." + key + ": expected a number");
    const double v = t->get<double>();
    const SettingRange& range = find_setting(setting)->range;
    if (!range.contains(v)) throw InvalidInput(where + "." + key + ": must be in " + range.text());
    out = v;
}

json lobe_model_to_json(const LobeModel& m)
{
    json positions = json::array();
    for (const glm::vec3& p : m.mesh.positions)
        for (int k = 0; k < 3; ++k) positions.push_back(p[k]);
    json triangles = json::array();
    for (const std::array<int, 3>& t : m.mesh.triangles)
        for (int k = 0; k < 3; ++k) triangles.push_back(t[static_cast<std::size_t>(k)]);
    return json{{"source", m.source}, {"positions", std::move(positions)}, {"triangles", std::move(triangles)}};
}

LobeModel lobe_model_from_json(const json& j, const std::string& w)
{
    if (!j.is_object()) throw InvalidInput(w + ": expected an object");
    check_keys(j, {"source", "positions", "triangles"}, w);
    LobeModel m;
    read_string(j, "source", m.source, w);
    if (m.source.size() > 4096) throw InvalidInput(w + ".source: longer than 4096 characters");
    const auto p = j.find("positions");
    if (p == j.end() || !p->is_array() || p->size() % 3 != 0)
        throw InvalidInput(w + ".positions: expected an array of x, y, z numbers");
    if (p->size() / 3 > kMaxLobeModelVertices)
        throw InvalidInput(w + ".positions: more than " + std::to_string(kMaxLobeModelVertices) + " vertices");
    m.mesh.positions.resize(p->size() / 3);
    for (std::size_t i = 0; i < p->size(); ++i) {
        const json& v = (*p)[i];
        if (!v.is_number()) throw InvalidInput(w + ".positions: expected numbers");
        m.mesh.positions[i / 3][static_cast<int>(i % 3)] = json_float(v);
    }
    const auto t = j.find("triangles");
    if (t == j.end() || !t->is_array() || t->size() % 3 != 0)
        throw InvalidInput(w + ".triangles: expected an array of vertex index triples");
    if (t->size() / 3 > kMaxLobeModelTriangles)
        throw InvalidInput(w + ".triangles: more than " + std::to_string(kMaxLobeModelTriangles) + " triangles");
    m.mesh.triangles.resize(t->size() / 3);
    const auto n = static_cast<std::int64_t>(m.mesh.positions.size());
    for (std::size_t i = 0; i < t->size(); ++i) {
        const json& v = (*t)[i];
        if (!v.is_number_integer()) throw InvalidInput(w + ".triangles: expected integer vertex indices");
        const auto k = v.get<std::int64_t>();
        // Checked before narrowing to int; validate_lobe_model checks the rest.
        if (k < 0 || k >= n) throw InvalidInput(w + ".triangles: vertex index " + std::to_string(k) + " out of range");
        m.mesh.triangles[i / 3][i % 3] = static_cast<int>(k);
    }
    validate_lobe_model(m, w);
    return m;
}

std::int64_t read_id(const json& j, const char* key, const std::string& where)
{
    auto it = j.find(key);
    if (it == j.end() || !it->is_number_integer())
        throw InvalidInput(where + "." + key + ": expected an integer");
    return it->get<std::int64_t>();
}

Stroke stroke_from_json(const json& j, const std::string& where)
{
    if (!j.is_object()) throw InvalidInput(where + ": expected an object");
    Stroke s;
    s.id = read_id(j, "id", where);
    auto kind = j.find("kind");
    if (kind == j.end() || !kind->is_string()) throw InvalidInput(where + ".kind: expected a string");
    try {
        s.kind = stroke_kind_from_name(kind->get<std::string>());
    } catch (const InvalidInput& e) {
        throw InvalidInput(where + ".kind: " + e.what());
    }
    if (auto h = j.find("hand"); h != j.end()) {
        if (!h->is_string() || (*h != "left" && *h != "right"))
            throw InvalidInput(where + ".hand: expected \"left\" or \"right\"");
        s.hand = *h == "left" ? Hand::Left : Hand::Right;
    }
    if (auto c = j.find("closed"); c != j.end()) {
        if (!c->is_boolean()) throw InvalidInput(where + ".closed: expected true or false");
        s.closed = c->get<bool>();
    }
    auto pts = j.find("points");
    if (pts == j.end() || !pts->is_array()) throw InvalidInput(where + ".points: expected an array");
    if (pts->size() > kMaxStrokePoints)
        throw InvalidInput(where + ".points: " + too_many(pts->size(), kMaxStrokePoints, "points"));
    const json* times = nullptr;
    if (auto t = j.find("times"); t != j.end()) {
        if (!t->is_array() || t->size() != pts->size())
            throw InvalidInput(where + ".times: expected one time per point");
        times = &*t;
    }
    s.points.reserve(pts->size());
    for (std::size_t i = 0; i < pts->size(); ++i) {
        const json& p = (*pts)[i];
        if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
            throw InvalidInput(where + ".points[" + std::to_string(i) + "]: expected [x, y, z]");
        StrokePoint sp;
        sp.position = {json_float(p[0]), json_float(p[1]), json_float(p[2])};
        if (!std::isfinite(sp.position.x) || !std::isfinite(sp.position.y) || !std::isfinite(sp.position.z))
            throw InvalidInput(where + ".points[" + std::to_string(i) + "]: not finite");
        if (times) {
            if (!(*times)[i].is_number()) throw InvalidInput(where + ".times: expected numbers");
            sp.time = (*times)[i].get<double>();
        }
        s.points.push_back(sp);
    }
    if (const std::string why = stroke_points_problem(s); !why.empty()) throw InvalidInput(where + ".points: " + why);
    return s;
}

} // namespace

void validate_lobe_model(const LobeModel& m, const std::string& w)
{
    if (m.mesh.positions.size() > kMaxLobeModelVertices)
        throw InvalidInput(w + ".positions: more than " + std::to_string(kMaxLobeModelVertices) + " vertices");
    if (m.mesh.triangles.size() > kMaxLobeModelTriangles)
        throw InvalidInput(w + ".triangles: more than " + std::to_string(kMaxLobeModelTriangles) + " triangles");
    if (m.mesh.triangles.size() < 4) throw InvalidInput(w + ".triangles: a closed mesh needs at least 4 triangles");
    for (const glm::vec3& p : m.mesh.positions)
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(p[k]) || std::abs(p[k]) > 1000.0f)
                throw InvalidInput(w + ".positions: a coordinate is not finite or beyond 1 km");
    const auto n = static_cast<std::int64_t>(m.mesh.positions.size());
    for (const std::array<int, 3>& tri : m.mesh.triangles) {
        for (int k : tri)
            if (k < 0 || k >= n) throw InvalidInput(w + ".triangles: vertex index " + std::to_string(k) + " out of range");
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
            throw InvalidInput(w + ".triangles: a triangle repeats a vertex");
    }
}

json document_to_json(const Document& doc)
{
    json strokes = json::array();
    for (const Stroke& s : doc.strokes) strokes.push_back(stroke_to_json(s));
    json lobes = json::array();
    for (const LobeRecord& l : doc.lobes)
    {
        json r{{"id", l.id}, {"strokes", l.stroke_ids}, {"mesh", l.mesh_file}};
        if (l.split_angle_deg) r["split_angle_deg"] = *l.split_angle_deg;
        if (!l.species.empty()) r["species"] = l.species;
        if (l.leaf_length_m) r["leaf_length_m"] = *l.leaf_length_m;
        if (l.leaves_per_node) r["leaves_per_node"] = *l.leaves_per_node;
        if (l.seed) r["seed"] = *l.seed;
        if (l.model) r["model"] = lobe_model_to_json(*l.model);
        lobes.push_back(std::move(r));
    }
    json edits = json::array();
    for (const EditOperation& e : doc.edits)
        edits.push_back({{"id", e.id}, {"type", e.type}, {"target", e.target}, {"params", e.params}});
    json trees = json::array();
    for (const TreeInstance& t : doc.trees) {
        json m = json::array();
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m.push_back(t.transform[c][r]);
        trees.push_back({{"id", t.id}, {"transform", m}, {"seed", t.seed}, {"lobes", t.lobe_ids}});
    }
    json out{{"format", "lobesketch-session"},
             {"version", doc.version},
                {"source_recording", doc.source_recording},
                {"seed", doc.seed},
                {"settings", settings_json(doc.settings)},
                {"strokes", std::move(strokes)},
                {"lobes", std::move(lobes)},
                {"edits", std::move(edits)},
                {"trees", std::move(trees)}};
    // Where in source_recording this document stands (docs/crash-safety.md).
    if (doc.recording_frames) {
        out["recording_frames"] = *doc.recording_frames;
        if (doc.recording_finished) out["recording_finished"] = true;
    }
    return out;
}

Document document_from_json(const json& j)
{
    if (!j.is_object()) throw InvalidInput("not a session document (expected a JSON object)");
    auto fmt = j.find("format");
    if (fmt == j.end() || *fmt != "lobesketch-session")
        throw InvalidInput("not a session document (missing \"format\": \"lobesketch-session\")");
    auto ver = j.find("version");
    if (ver == j.end() || !ver->is_number_integer()) throw InvalidInput("version: expected an integer");
    // Read wide: a version beyond int must not wrap into a supported one.
    const bool huge = ver->is_number_unsigned() && ver->get<std::uint64_t>() > std::uint64_t{1} << 32;
    const std::int64_t version = huge ? -1 : ver->get<std::int64_t>();
    if (version < 1 || version > kDocumentVersion)
        throw InvalidInput("unsupported session version " + ver->dump() + " (this build reads 1.." +
                           std::to_string(kDocumentVersion) + ")");
    Document doc;
    doc.version = kDocumentVersion;
    if (auto it = j.find("source_recording"); it != j.end()) {
        if (!it->is_string()) throw InvalidInput("source_recording: expected a string");
        doc.source_recording = it->get<std::string>();
    }
    if (auto it = j.find("recording_frames"); it != j.end()) {
        if (!it->is_number_integer() || it->get<std::int64_t>() < 0 ||
            it->get<std::uint64_t>() > kMaxDocumentRecordingFrames)
            throw InvalidInput("recording_frames: expected an integer in [0, " +
                               std::to_string(kMaxDocumentRecordingFrames) + "]");
        doc.recording_frames = it->get<std::uint64_t>();
    }
    if (auto it = j.find("recording_finished"); it != j.end()) {
        if (!it->is_boolean()) throw InvalidInput("recording_finished: expected true or false");
        if (*it && !doc.recording_frames) throw InvalidInput("recording_finished: needs recording_frames");
        doc.recording_finished = it->get<bool>();
    }
    if (auto it = j.find("seed"); it != j.end()) {
        if (!it->is_number_unsigned()) throw InvalidInput("seed: expected a non-negative integer");
        doc.seed = it->get<std::uint64_t>();
    }
    if (auto it = j.find("settings"); it != j.end()) doc.settings = settings_from_json(*it);

    auto array_of = [&](const char* key) -> const json* {
        auto it = j.find(key);
        if (it == j.end()) return nullptr;
        if (!it->is_array()) throw InvalidInput(std::string(key) + ": expected an array");
        return &*it;
    };
    if (const json* a = array_of("strokes")) {
        if (a->size() > kMaxDocumentStrokes) throw InvalidInput("strokes: " + too_many(a->size(), kMaxDocumentStrokes, "strokes"));
        std::unordered_set<std::int64_t> ids;
        for (std::size_t i = 0; i < a->size(); ++i) {
            const std::string w = "strokes[" + std::to_string(i) + "]";
            doc.strokes.push_back(stroke_from_json((*a)[i], w));
            if (!ids.insert(doc.strokes.back().id).second)
                throw InvalidInput(w + ".id: stroke id " + std::to_string(doc.strokes.back().id) + " is used twice");
        }
    }
    if (const json* a = array_of("lobes")) {
        if (a->size() > kMaxDocumentLobes) throw InvalidInput("lobes: " + too_many(a->size(), kMaxDocumentLobes, "lobes"));
        std::unordered_set<std::int64_t> ids;
        for (std::size_t i = 0; i < a->size(); ++i) {
            const json& l = (*a)[i];
            const std::string w = "lobes[" + std::to_string(i) + "]";
            if (!l.is_object()) throw InvalidInput(w + ": expected an object");
            LobeRecord r;
            r.id = read_id(l, "id", w);
            if (!ids.insert(r.id).second) throw InvalidInput(w + ".id: lobe id " + std::to_string(r.id) + " is used twice");
            if (auto s = l.find("strokes"); s != l.end()) {
                if (!s->is_array()) throw InvalidInput(w + ".strokes: expected an array of ids");
                if (s->size() > kMaxDocumentStrokes)
                    throw InvalidInput(w + ".strokes: " + too_many(s->size(), kMaxDocumentStrokes, "stroke ids"));
                for (const json& id : *s) {
                    if (!id.is_number_integer()) throw InvalidInput(w + ".strokes: expected integer ids");
                    r.stroke_ids.push_back(id.get<std::int64_t>());
                }
            }
            if (auto m = l.find("mesh"); m != l.end()) {
                if (!m->is_string()) throw InvalidInput(w + ".mesh: expected a file name");
                r.mesh_file = m->get<std::string>();
            }
            read_override(l, "split_angle_deg", "growth.split_angle_deg", r.split_angle_deg, w);
            if (auto sp = l.find("species"); sp != l.end()) {
                if (!sp->is_string() || sp->get<std::string>().size() > 64)
                    throw InvalidInput(w + ".species: expected a name of at most 64 characters");
                r.species = sp->get<std::string>();
            }
            read_override(l, "leaf_length_m", "leaves.length_m", r.leaf_length_m, w);
            if (auto t = l.find("leaves_per_node"); t != l.end()) {
                if (!t->is_number_integer()) throw InvalidInput(w + ".leaves_per_node: expected an integer");
                const auto v = t->get<std::int64_t>();
                const SettingRange& range = find_setting("leaves.per_node")->range;
                if (!range.contains(static_cast<double>(v)))
                    throw InvalidInput(w + ".leaves_per_node: must be in " + range.text());
                r.leaves_per_node = static_cast<int>(v);
            }
            if (auto t = l.find("seed"); t != l.end()) {
                if (!t->is_number_unsigned()) throw InvalidInput(w + ".seed: expected a non-negative integer");
                r.seed = t->get<std::uint64_t>();
            }
            if (auto m = l.find("model"); m != l.end()) {
                r.model = std::make_shared<const LobeModel>(lobe_model_from_json(*m, w + ".model"));
                if (!r.stroke_ids.empty()) throw InvalidInput(w + ": a lobe made from a mesh has no strokes");
            }
            doc.lobes.push_back(std::move(r));
        }
    }
    if (const json* a = array_of("edits")) {
        if (a->size() > kMaxDocumentEdits) throw InvalidInput("edits: " + too_many(a->size(), kMaxDocumentEdits, "edits"));
        for (std::size_t i = 0; i < a->size(); ++i) {
            const json& e = (*a)[i];
            const std::string w = "edits[" + std::to_string(i) + "]";
            if (!e.is_object()) throw InvalidInput(w + ": expected an object");
            EditOperation op;
            op.id = read_id(e, "id", w);
            auto t = e.find("type");
            if (t == e.end() || !t->is_string()) throw InvalidInput(w + ".type: expected a string");
            op.type = t->get<std::string>();
            op.target = read_id(e, "target", w);
            if (auto p = e.find("params"); p != e.end()) op.params = *p;
            doc.edits.push_back(std::move(op));
        }
    }
    if (const json* a = array_of("trees")) {
        if (a->size() > kMaxDocumentTrees) throw InvalidInput("trees: " + too_many(a->size(), kMaxDocumentTrees, "trees"));
        for (std::size_t i = 0; i < a->size(); ++i) {
            const json& t = (*a)[i];
            const std::string w = "trees[" + std::to_string(i) + "]";
            if (!t.is_object()) throw InvalidInput(w + ": expected an object");
            TreeInstance ti;
            ti.id = read_id(t, "id", w);
            if (auto m = t.find("transform"); m != t.end()) {
                if (!m->is_array() || m->size() != 16) throw InvalidInput(w + ".transform: expected 16 numbers");
                for (int k = 0; k < 16; ++k) {
                    if (!(*m)[k].is_number()) throw InvalidInput(w + ".transform: expected 16 numbers");
                    const float v = json_float((*m)[k]);
                    if (!std::isfinite(v)) throw InvalidInput(w + ".transform: not finite");
                    ti.transform[k / 4][k % 4] = v;
                }
            }
            if (auto s = t.find("seed"); s != t.end()) {
                if (!s->is_number_unsigned()) throw InvalidInput(w + ".seed: expected a non-negative integer");
                ti.seed = s->get<std::uint64_t>();
            }
            if (auto l = t.find("lobes"); l != t.end()) {
                if (!l->is_array()) throw InvalidInput(w + ".lobes: expected an array of ids");
                if (l->size() > kMaxDocumentLobes)
                    throw InvalidInput(w + ".lobes: " + too_many(l->size(), kMaxDocumentLobes, "lobe ids"));
                for (const json& id : *l) {
                    if (!id.is_number_integer()) throw InvalidInput(w + ".lobes: expected integer ids");
                    ti.lobe_ids.push_back(id.get<std::int64_t>());
                }
            }
            doc.trees.push_back(std::move(ti));
        }
    }
    return doc;
}

void save_document(const std::string& path, const Document& doc)
{
    write_file_atomic(path, document_to_json(doc).dump(1) + "\n");
}

Document load_document(const std::string& path)
{
    std::string text = read_file_limited(path, kMaxDocumentBytes);
    json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) throw FileError(path, "not valid JSON");
    try {
        return document_from_json(j);
    } catch (const InvalidInput& e) {
        throw FileError(path, e.what());
    }
}

std::string previous_autosave_path(const std::string& path) { return path + ".1"; }

void save_autosave(const std::string& path, const Document& doc)
{
    // The file about to be replaced becomes the previous generation: a second name for it,
    // moved into place by rename, so PATH.1 too is always a whole document.
    std::error_code ec;
    if (std::filesystem::is_regular_file(path, ec)) {
        const std::string previous = previous_autosave_path(path);
        const std::string link = previous + ".tmp";
        std::filesystem::remove(link, ec);
        std::filesystem::create_hard_link(path, link, ec);
        if (!ec) std::filesystem::rename(link, previous, ec);
        if (ec) std::filesystem::remove(link, ec);
    }
    save_document(path, doc);
}

} // namespace lobe
