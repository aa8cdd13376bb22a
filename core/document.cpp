#include "core/document.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <unordered_set>
#include <variant>
#include <nlohmann/json.hpp>

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

namespace {

json grower_to_json(const GrowerChoice& g)
{
    json params = json::object();
    for (const auto& [key, value] : g.params)
        std::visit([&, k = &key](const auto& v) { params[*k] = v; }, value);
    return json{{"name", g.name}, {"version", g.version}, {"params", std::move(params)}};
}

/// `{"name": NAME, "version": N, "params": {KEY: flag, number or text, …}}`; the growers
/// themselves check the name and the parameters (app/session/session_file.h).
GrowerChoice grower_from_json(const json& j, const std::string& w)
{
    if (!j.is_object()) throw InvalidInput(w + ": expected an object");
    check_keys(j, {"name", "version", "params"}, w);
    GrowerChoice g;
    const auto name = j.find("name");
    if (name == j.end() || !name->is_string()) throw InvalidInput(w + ".name: expected a grower's name");
    g.name = name->get<std::string>();
    const bool well_formed = !g.name.empty() && g.name.size() <= kMaxGrowerNameLength &&
                             std::all_of(g.name.begin(), g.name.end(), [](char c) {
                                 return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-';
                             });
    if (!well_formed)
        throw InvalidInput(w + ".name: expected lower-case letters, digits and '-' (at most " +
                           std::to_string(kMaxGrowerNameLength) + ")");
    if (const auto v = j.find("version"); v != j.end()) {
        if (!v->is_number_integer() || v->get<std::int64_t>() < 1 || v->get<std::int64_t>() > 1000000)
            throw InvalidInput(w + ".version: expected an integer in [1, 1000000]");
        g.version = v->get<int>();
    }
    if (const auto p = j.find("params"); p != j.end()) {
        if (!p->is_object()) throw InvalidInput(w + ".params: expected an object");
        if (p->size() > kMaxGrowerParams)
            throw InvalidInput(w + ".params: more than " + std::to_string(kMaxGrowerParams) + " parameters");
        for (auto it = p->begin(); it != p->end(); ++it) {
            const std::string wk = w + ".params." + it.key();
            if (it.key().empty() || it.key().size() > kMaxGrowerNameLength)
                throw InvalidInput(w + ".params: a parameter name is empty or longer than " +
                                   std::to_string(kMaxGrowerNameLength) + " characters");
            const json& v = it.value();
            if (v.is_boolean()) g.params[it.key()] = v.get<bool>();
            else if (v.is_number_integer()) {
                if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
                    throw InvalidInput(wk + ": a whole number beyond 2^63");
                g.params[it.key()] = v.get<std::int64_t>();
            } else if (v.is_number_float()) {
                if (!std::isfinite(v.get<double>())) throw InvalidInput(wk + ": not a finite number");
                g.params[it.key()] = v.get<double>();
            } else if (v.is_string()) {
                if (v.get_ref<const std::string&>().size() > kMaxGrowerParamTextBytes)
                    throw InvalidInput(wk + ": a text longer than " + std::to_string(kMaxGrowerParamTextBytes) + " bytes");
                g.params[it.key()] = v.get<std::string>();
            } else {
                throw InvalidInput(wk + ": expected true, false, a number or a text");
            }
        }
    }
    return g;
}

// Edit operations (core/edits.h): read and checked here once, when a document loads; written
// back as read (coordinates are kept as the doubles the file held, a point keeps or lacks its
// time), so a document the program wrote is saved again byte for byte.

json xyz_json(const glm::dvec3& p) { return json::array({p.x, p.y, p.z}); }

json edit_to_json(const EditOperation& op)
{
    json path = json::array();
    for (const DragPoint& p : op.path) {
        json q = xyz_json(p.position);
        if (p.time) q.push_back(*p.time);
        path.push_back(std::move(q));
    }
    json params{{"hand", hand_name(op.hand)}, {"path", std::move(path)}};
    if (const EditStrokeParams* s = op.stroke_params()) {
        if (s->pick_distance_m) params["pick_distance_m"] = *s->pick_distance_m;
        if (s->half_length_m) params["half_length_m"] = *s->half_length_m;
        if (s->other_tip) params["other_tip"] = xyz_json(*s->other_tip);
    }
    if (const LobeTransformParams* t = op.transform_params()) {
        if (t->centre) params["centre"] = xyz_json(*t->centre);
        if (t->strokes) params["strokes"] = *t->strokes;
    }
    return {{"id", op.id}, {"type", edit_kind_name(op.kind())}, {"target", op.target}, {"params", std::move(params)}};
}

/// The first three numbers of `j`, an array of `min_size` to `max_size` numbers; false when
/// it is not one.
bool read_numbers(const json& j, std::size_t min_size, std::size_t max_size, glm::dvec3& xyz, std::optional<double>& fourth)
{
    if (!j.is_array() || j.size() < min_size || j.size() > max_size) return false;
    for (const json& v : j)
        if (!v.is_number()) return false;
    xyz = {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
    fourth.reset();
    if (j.size() > 3) fourth = j[3].get<double>();
    return true;
}

glm::dvec3 read_xyz(const json& j, const std::string& where)
{
    glm::dvec3 p;
    std::optional<double> none;
    if (!read_numbers(j, 3, 3, p, none)) throw InvalidInput(where + ": expected [x, y, z] numbers");
    return p;
}

/// The keys a kind's params may hold besides "hand" and "path".
std::vector<const char*> param_keys(EditKind kind)
{
    switch (kind) {
    case EditKind::EditStroke: return {"pick_distance_m", "half_length_m", "other_tip"};
    case EditKind::MoveLobe:
    case EditKind::RotateLobe:
    case EditKind::ScaleLobe: return {"centre", "strokes"};
    case EditKind::DeformLobe: break;
    }
    return {};
}

EditOperation edit_from_json(const json& e, const std::string& w)
{
    if (!e.is_object()) throw InvalidInput(w + ": expected an object");
    for (auto it = e.begin(); it != e.end(); ++it)
        if (it.key() != "id" && it.key() != "type" && it.key() != "target" && it.key() != "params")
            throw InvalidInput(w + ": unknown key '" + it.key() + "'");
    EditOperation op;
    op.id = read_id(e, "id", w);
    auto t = e.find("type");
    if (t == e.end() || !t->is_string()) throw InvalidInput(w + ".type: expected a string");
    const std::optional<EditKind> kind = edit_kind_from_name(t->get_ref<const std::string&>());
    if (!kind) throw InvalidInput(w + ".type: unknown edit type \"" + t->get<std::string>() + "\"");
    op.params = edit_params_of(*kind);
    op.target = read_id(e, "target", w);

    const std::string pw = w + ".params";
    auto pit = e.find("params");
    if (pit == e.end() || !pit->is_object()) throw InvalidInput(pw + ": expected an object");
    const json& p = *pit;
    const std::vector<const char*> keys = param_keys(*kind);
    for (auto it = p.begin(); it != p.end(); ++it) {
        bool known = it.key() == "hand" || it.key() == "path";
        for (const char* k : keys) known = known || it.key() == k;
        if (!known) throw InvalidInput(pw + ": unknown key '" + it.key() + "' for " + edit_kind_name(*kind));
    }

    auto hand = p.find("hand");
    if (hand == p.end() || !hand->is_string() || (*hand != "left" && *hand != "right"))
        throw InvalidInput(pw + ".hand: expected \"left\" or \"right\"");
    op.hand = *hand == "left" ? Hand::Left : Hand::Right;
    auto path = p.find("path");
    if (path == p.end() || !path->is_array() || path->empty())
        throw InvalidInput(pw + ".path: expected a non-empty array of [x, y, z] or [x, y, z, t] points");
    if (path->size() > kMaxStrokePoints)
        throw InvalidInput(pw + ".path: " + std::to_string(path->size()) + " points, more than the " +
                           std::to_string(kMaxStrokePoints) + " a path may have");
    op.path.resize(path->size());
    for (std::size_t i = 0; i < path->size(); ++i)
        if (!read_numbers((*path)[i], 3, 4, op.path[i].position, op.path[i].time))
            throw InvalidInput(pw + ".path[" + std::to_string(i) + "]: expected [x, y, z] or [x, y, z, t] numbers");

    auto length = [&](const char* key, std::optional<double>& out) {
        auto it = p.find(key);
        if (it == p.end()) return;
        if (!it->is_number()) throw InvalidInput(pw + "." + key + ": expected a positive number");
        out = it->get<double>();
    };
    if (auto* s = std::get_if<EditStrokeParams>(&op.params)) {
        length("pick_distance_m", s->pick_distance_m);
        length("half_length_m", s->half_length_m);
        if (auto o = p.find("other_tip"); o != p.end()) s->other_tip = read_xyz(*o, pw + ".other_tip");
    }
    if (LobeTransformParams* tr = op.transform_params()) {
        if (auto c = p.find("centre"); c != p.end()) tr->centre = read_xyz(*c, pw + ".centre");
        if (auto s = p.find("strokes"); s != p.end()) {
            if (!s->is_array()) throw InvalidInput(pw + ".strokes: expected an array of stroke ids");
            if (s->size() > kMaxDocumentStrokes)
                throw InvalidInput(pw + ".strokes: " + too_many(s->size(), kMaxDocumentStrokes, "stroke ids"));
            tr->strokes.emplace();
            tr->strokes->reserve(s->size());
            for (const json& id : *s) {
                if (!id.is_number_integer()) throw InvalidInput(pw + ".strokes: expected integer ids");
                tr->strokes->push_back(id.get<std::int64_t>());
            }
        }
    }
    // The values: finite, within the stroke limits, positive lengths, a centre where needed.
    if (const std::string why = edit_operation_problem(op); !why.empty()) throw InvalidInput(w + "." + why);
    return op;
}

} // namespace

const GrowerChoice& scene_grower(const Document& doc)
{
    static const GrowerChoice kDefault;
    return doc.trees.empty() ? kDefault : doc.trees.front().grower;
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
    for (const EditOperation& e : doc.edits) edits.push_back(edit_to_json(e));
    json trees = json::array();
    for (const TreeInstance& t : doc.trees) {
        json m = json::array();
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m.push_back(t.transform[c][r]);
        trees.push_back({{"id", t.id}, {"transform", m}, {"seed", t.seed}, {"lobes", t.lobe_ids},
                         {"grower", grower_to_json(t.grower)}});
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
        for (std::size_t i = 0; i < a->size(); ++i)
            doc.edits.push_back(edit_from_json((*a)[i], "edits[" + std::to_string(i) + "]"));
    }
    if (const json* a = array_of("trees")) {
        if (a->size() > kMaxDocumentTrees) throw InvalidInput("trees: " + too_many(a->size(), kMaxDocumentTrees, "trees"));
        for (std::size_t i = 0; i < a->size(); ++i) {
            const json& t = (*a)[i];
            const std::string w = "trees[" + std::to_string(i) + "]";
            if (!t.is_object()) throw InvalidInput(w + ": expected an object");
            check_keys(t, {"id", "transform", "seed", "lobes", "grower"}, w);
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
            // Written before trees named their grower: the default grower.
            if (auto g = t.find("grower"); g != t.end()) ti.grower = grower_from_json(*g, w + ".grower");
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
