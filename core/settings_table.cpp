#include "core/settings_table.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <utility>

#include "core/errors.h"

namespace lobe {

namespace {

using Weights = std::map<std::string, double>;

/// Most subtree weights a setting holds, and the largest weight.
constexpr std::size_t kMaxWeights = 256;
constexpr double kMaxWeight = 1e6;
/// A Name setting without choices: 1 to this many characters.
constexpr std::size_t kMaxNameLength = 64;

/// A member of section struct S holding a setting, by its type (SettingType order).
template <class S>
using Member = std::variant<double S::*, int S::*, std::string S::*, double (S::*)[3], Weights S::*>;

/// One row of a section's table: key, member, range or allowed values, doc.
template <class S>
struct Field {
    const char* name;
    Member<S> member;
    SettingRange range;
    std::vector<std::string> choices;
    const char* doc;

    /// A number or integer with its range in interval notation.
    Field(const char* n, Member<S> m, const char* interval, const char* d)
        : name(n), member(m), range(SettingRange::parse(interval)), doc(d)
    {
    }
    /// A name from a list.
    Field(const char* n, Member<S> m, std::vector<std::string> allowed, const char* d)
        : name(n), member(m), choices(std::move(allowed)), doc(d)
    {
    }
    /// A colour, weights, or a name of 1 to 64 characters: their limits are their type's.
    Field(const char* n, Member<S> m, const char* d) : name(n), member(m), doc(d) {}
};

// ---------------------------------------------------------------------------------------
// The tables. Defaults are the member initializers in core/settings.h.

const std::vector<Field<OneEuroOptions>>& one_euro_fields()
{
    static const std::vector<Field<OneEuroOptions>> f = {
        {"min_cutoff_hz", &OneEuroOptions::min_cutoff_hz, "(0, 1000]", "cutoff at rest (Hz): lower removes more jitter"},
        {"beta", &OneEuroOptions::beta, "[0, 10000]", "speed coefficient (per m/s): higher removes more lag when moving"},
        {"d_cutoff_hz", &OneEuroOptions::d_cutoff_hz, "(0, 1000]", "cutoff of the speed estimate (Hz)"},
    };
    return f;
}

const std::vector<Field<InputOptions>>& input_fields()
{
    static const std::vector<Field<InputOptions>> f = {
        {"pinch_start_m", &InputOptions::pinch_start_m, "(0, 0.1)",
         "a pinch starts when the thumb-tip/index-tip gap (centre distance minus both joint radii) falls below this"},
        {"pinch_release_m", &InputOptions::pinch_release_m, "(pinch_start_m, 0.2)",
         "a pinch ends when that gap rises above this"},
        {"pinch_min_hold_s", &InputOptions::pinch_min_hold_s, "[0, 1]",
         "a pinch needs the gap below pinch_start_m this long (debounces single-frame dips)"},
        {"curl_grab", &InputOptions::curl_grab, "(0, 1]",
         "curl (bend over 270°) above which middle, ring and little count as curled; all three curled is a grab, never a pinch"},
        {"curl_release", &InputOptions::curl_release, "[0, curl_grab)",
         "curl below which a curled finger counts as open again"},
        {"curl_point_index_max", &InputOptions::curl_point_index_max, "(0, 1)",
         "index curl below which the index counts as straight: straight index and the others curled is a point"},
        {"min_point_distance_m", &InputOptions::min_point_distance_m, "[0.0005, 0.1]",
         "a new stroke point is kept only when the fingertip moved at least this far (the paper's rule)"},
        {"bridge_loss_s", &InputOptions::bridge_loss_s, "[0, 5]",
         "tracking loss shorter than this is bridged; longer ends the stroke"},
        {"min_stroke_length_m", &InputOptions::min_stroke_length_m, "[0, 10]",
         "strokes shorter than this (polyline length) are discarded"},
        {"min_stroke_points", &InputOptions::min_stroke_points, "[2, 1000]", "strokes of fewer points are discarded"},
        {"max_hand_speed_mps", &InputOptions::max_hand_speed_mps, "(0.5, 100]",
         "a hand moving faster than this between two frames is a tracking glitch: the frame counts as lost"},
    };
    return f;
}

const std::vector<Field<LobeSettings>>& lobe_fields()
{
    static const std::vector<Field<LobeSettings>> f = {
        {"edge_length_m", &LobeSettings::edge_length_m, "[0.005, 0.5]",
         "attractor spacing: every lobe is remeshed to this edge length, so all lobes carry the same attractor density"},
        {"remesh_iterations", &LobeSettings::remesh_iterations, "[0, 20]",
         "rounds of isotropic remeshing of every lobe, from strokes and from models (0: not remeshed)"},
        {"closed_gap_fraction", &LobeSettings::closed_gap_fraction, "(0, 0.5]",
         "a stroke is closed when the gap between its ends is below this fraction of its length and below closed_gap_max_m"},
        {"closed_gap_max_m", &LobeSettings::closed_gap_max_m, "(0, 1]",
         "the largest gap between its ends a closed stroke may have"},
        {"pinch_roi_radius_m", &LobeSettings::pinch_roi_radius_m, "[0.01, 2]",
         "a pinch edit moves the lobe vertices within this distance (along edges) of its handle"},
        {"pinch_pick_distance_m", &LobeSettings::pinch_pick_distance_m, "(0, 0.5]",
         "a pinch edit's handle is the lobe vertex nearest the pinch within this distance (the lobe itself is picked "
         "by the drag's lobe pick distance, EditPickOptions)"},
    };
    return f;
}

const std::vector<Field<GrowthSettings>>& growth_fields()
{
    static const std::vector<Field<GrowthSettings>> f = {
        {"species", &GrowthSettings::species, "species preset (growth/data/species/) the appearance settings came from"},
        {"split_angle_deg", &GrowthSettings::split_angle_deg, "[5, 180]",
         "split angle t: a cluster spanning more than this horizontally or vertically is split; smaller gives denser "
         "branching"},
        {"alpha", &GrowthSettings::alpha, "[-10, 10]", "weight of the node's own direction in V_A (the paper's α)"},
        {"beta", &GrowthSettings::beta, "[-10, 10]",
         "weight of gravity (0, −1, 0) in V_A (the paper's β): negative grows upwards"},
        {"growth_ratio", &GrowthSettings::growth_ratio, "(0, 1]",
         "a subtree's length as a fraction of the signed distance from its node to the lobe surface along V_A"},
        {"stop_distance_m", &GrowthSettings::stop_distance_m, "[0.001, 0.5]",
         "a node closer than this to the lobe surface along V_A stops; its attractors leave the next iteration"},
        {"kill_distance_m", &GrowthSettings::kill_distance_m, "[0.002, 1]",
         "most distance at which a node reaches (and removes) an attractor; below it the distance follows the "
         "node's subtree scale (a quarter of its subtree's length), so the stop rule decides where growth ends"},
        {"skeleton_spacing_m", &GrowthSettings::skeleton_spacing_m, "[0.002, 0.5]",
         "spacing of skeleton nodes along trunk strokes"},
        {"max_iterations", &GrowthSettings::max_iterations, "[1, 1000]", "most growth iterations per lobe"},
        {"max_nodes", &GrowthSettings::max_nodes, "[100, 5000000]", "most nodes per lobe"},
        {"subtree_weights", &GrowthSettings::subtree_weights,
         "relative weights of the library subtrees (growth/data/subtrees.json) by name; names left out weigh 0; none: "
         "all weigh the same"},
        {"leader", &GrowthSettings::leader, "[0, 1]",
         "1: the trunk (default or sketched) continues from its highest point as a leader up through the crown "
         "(excurrent, a conifer); 0: it ends where it ends (decurrent)"},
        {"whorl_spacing", &GrowthSettings::whorl_spacing, "[0, 0.5]",
         "spacing of the leader's nodes as a fraction of the crown height, so laterals grow in whorls; 0: "
         "skeleton_spacing_m"},
        {"droop", &GrowthSettings::droop, "[0, 1]",
         "share by which a lateral turns from its grown direction towards straight down, growing from its base "
         "to its end"},
        {"hang", &GrowthSettings::hang, "[0, 1]",
         "share by which the outer part of every lateral turns to hang straight down (weeping twigs)"},
        {"height_m", &GrowthSettings::height_m, "[0, 1000]",
         "height of the exported tree: the structure is scaled about its base to this height, leaves and twig "
         "radii keep their size (real scale); 0: as sketched"},
    };
    return f;
}

const std::vector<Field<BranchSettings>>& branch_fields()
{
    static const std::vector<Field<BranchSettings>> f = {
        {"pipe_exponent", &BranchSettings::pipe_exponent, "[1, 4]", "pipe model exponent e: r_parent^e = Σ r_child^e"},
        {"tip_radius_m", &BranchSettings::tip_radius_m, "[0.0001, 0.05]", "branch radius at every tip"},
        {"radial_segments", &BranchSettings::radial_segments, "[3, 64]", "segments around a branch at LOD0"},
        {"ring_spacing_m", &BranchSettings::ring_spacing_m, "[0.002, 1]",
         "largest distance between rings along a branch at LOD0"},
        {"smoothing_iterations", &BranchSettings::smoothing_iterations, "[0, 20]",
         "Laplacian smoothing passes of branch curves"},
        {"bark_color", &BranchSettings::bark_color, "bark colour, linear RGB"},
        {"lod_count", &BranchSettings::lod_count, "[1, 6]", "levels of detail written (LOD0 … LOD{n−1})"},
        {"dbh_ratio", &BranchSettings::dbh_ratio, "[0, 0.2]",
         "at real scale (growth.height_m > 0): trunk diameter at breast height over tree height; > 0 fits the pipe "
         "exponent to it, 0 uses pipe_exponent"},
    };
    return f;
}

const std::vector<Field<LeafSettings>>& leaf_fields()
{
    static const std::vector<Field<LeafSettings>> f = {
        {"length_m", &LeafSettings::length_m, "[0.002, 1]", "leaf length"},
        {"width_m", &LeafSettings::width_m, "[0.001, 1]", "leaf width"},
        {"per_node", &LeafSettings::per_node, "[0, 64]", "leaves at each tip node"},
        {"deviation_deg", &LeafSettings::deviation_deg, "[0, 180]", "random deviation of a leaf from its branch direction"},
        {"color", &LeafSettings::color, "leaf colour, linear RGB"},
        {"shape", &LeafSettings::shape, std::vector<std::string>{"ovate", "round", "needle"}, "leaf texture"},
        {"spacing_m", &LeafSettings::spacing_m, "[0, 0.5]",
         "distance between leaves along a shoot: a shoot longer than per_node × this carries one leaf per spacing "
         "(at most 64); 0: all at the tip"},
    };
    return f;
}

// ---------------------------------------------------------------------------------------
// The tables flattened into one list of settings, each with its access to a Settings.

using Ref = std::variant<double*, int*, std::string*, double (*)[3], Weights*>;
using ConstRef = std::variant<const double*, const int*, const std::string*, const double (*)[3], const Weights*>;

struct Access {
    std::function<Ref(Settings&)> ref;
    std::function<ConstRef(const Settings&)> cref;
};

struct Table {
    std::vector<SettingInfo> infos;
    std::vector<Access> access; ///< parallel to infos
    std::vector<std::string> sections;
};

/// Appends a section's rows. `get` is a generic lambda giving the section of a Settings,
/// const or not; `what` prefixes each doc (the filters share one table).
template <class S, class Get>
void add_section(Table& t, const char* section, Get get, const std::vector<Field<S>>& fields, const char* what = nullptr)
{
    if (std::find(t.sections.begin(), t.sections.end(), section) == t.sections.end()) t.sections.emplace_back(section);
    for (const Field<S>& f : fields) {
        SettingInfo info;
        info.section = section;
        info.name = f.name;
        info.key = info.section + "." + info.name;
        info.type = static_cast<SettingType>(f.member.index());
        info.range = f.range;
        info.choices = f.choices;
        info.doc = what ? std::string(what) + ": " + f.doc : std::string(f.doc);
        Access a;
        std::visit(
            [&](auto m) {
                a.ref = [get, m](Settings& s) -> Ref { return &(get(s).*m); };
                a.cref = [get, m](const Settings& s) -> ConstRef { return &(get(s).*m); };
            },
            f.member);
        t.infos.push_back(std::move(info));
        t.access.push_back(std::move(a));
    }
}

const Table& table()
{
    static const Table t = [] {
        Table r;
        // The input section lists its filters first: they are read and checked before its
        // other settings.
        r.sections.emplace_back("input");
        add_section(r, "input.filter", [](auto& s) -> auto& { return s.input.filter; }, one_euro_fields(),
                    "drawing fingertip filter");
        add_section(r, "input.gap_filter", [](auto& s) -> auto& { return s.input.gap_filter; }, one_euro_fields(),
                    "thumb/index gap filter (lighter, so pinches register without delay)");
        add_section(r, "input", [](auto& s) -> auto& { return s.input; }, input_fields());
        add_section(r, "lobes", [](auto& s) -> auto& { return s.lobes; }, lobe_fields());
        add_section(r, "growth", [](auto& s) -> auto& { return s.growth; }, growth_fields());
        add_section(r, "branches", [](auto& s) -> auto& { return s.branches; }, branch_fields());
        add_section(r, "leaves", [](auto& s) -> auto& { return s.leaves; }, leaf_fields());
        return r;
    }();
    return t;
}

const Access& access_of(const SettingInfo& info)
{
    const Table& t = table();
    if (&info < t.infos.data() || &info >= t.infos.data() + t.infos.size())
        throw std::logic_error("a SettingInfo not of settings_table()");
    return t.access[static_cast<std::size_t>(&info - t.infos.data())];
}

/// `key` is `section` or lies below it.
bool in_section(const std::string& key, std::string_view section)
{
    return key.size() > section.size() && key.compare(0, section.size(), section) == 0 && key[section.size()] == '.';
}

std::string where(const SettingInfo& info) { return "settings." + info.key; }

double parse_number(std::string_view text, bool& ok)
{
    if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1); // "+25", as strtod reads it
    double v = 0.0;
    const char* end = text.data() + text.size();
    const auto [p, ec] = std::from_chars(text.data(), end, v);
    ok = ec == std::errc() && p == end && std::isfinite(v);
    return v;
}

/// Splits at commas (an empty text gives no parts).
std::vector<std::string_view> split_commas(std::string_view text)
{
    std::vector<std::string_view> parts;
    if (text.empty()) return parts;
    std::size_t from = 0;
    for (;;) {
        const std::size_t comma = text.find(',', from);
        parts.push_back(text.substr(from, comma == std::string_view::npos ? std::string_view::npos : comma - from));
        if (comma == std::string_view::npos) break;
        from = comma + 1;
    }
    return parts;
}

/// The value of the setting `name` of `info`'s section: the keyed end of a range.
double keyed_end(const Settings& s, const SettingInfo& info, const std::string& name)
{
    const SettingInfo* other = find_setting(info.section + "." + name);
    if (!other) throw std::logic_error("range of " + info.key + " names no setting " + name);
    const SettingValue v = get_setting(s, *other);
    if (const double* d = std::get_if<double>(&v)) return *d;
    if (const int* i = std::get_if<int>(&v)) return *i;
    throw std::logic_error("range of " + info.key + " names a setting that is not a number");
}

void check_color(const std::array<double, 3>& c, const std::string& w)
{
    for (double v : c)
        if (!(v >= 0.0 && v <= 1.0)) throw InvalidInput(w + ": components must be in [0, 1]");
}

void check_weights(const Weights& weights, const std::string& w)
{
    if (weights.size() > kMaxWeights) throw InvalidInput(w + ": too many entries");
    for (const auto& [name, v] : weights)
        if (!(v >= 0.0 && v <= kMaxWeight)) throw InvalidInput(w + "." + name + ": must be in [0, 1e6]");
}

/// The checks of check_setting, with the keyed range ends given (NaN: not checked).
void check_value(const SettingInfo& info, const SettingValue& value, double lo_value, double hi_value)
{
    const std::string w = where(info);
    switch (info.type) {
    case SettingType::Number:
    case SettingType::Integer: {
        const double v = info.type == SettingType::Number ? std::get<double>(value) : std::get<int>(value);
        if (!info.range.contains(v, lo_value, hi_value)) throw InvalidInput(w + " must be in " + info.range.text());
        break;
    }
    case SettingType::Name: {
        const std::string& v = std::get<std::string>(value);
        const bool ok = info.choices.empty() ? !v.empty() && v.size() <= kMaxNameLength
                                             : std::find(info.choices.begin(), info.choices.end(), v) != info.choices.end();
        if (!ok) throw InvalidInput(w + " must be " + info.allowed());
        break;
    }
    case SettingType::Color: check_color(std::get<std::array<double, 3>>(value), w); break;
    case SettingType::Weights: check_weights(std::get<Weights>(value), w); break;
    }
}

} // namespace

SettingRange SettingRange::parse(std::string_view text)
{
    auto bad = [&] { return std::logic_error("bad interval '" + std::string(text) + "'"); };
    if (text.size() < 5 || (text.front() != '[' && text.front() != '(') || (text.back() != ']' && text.back() != ')'))
        throw bad();
    const std::size_t comma = text.find(", ");
    if (comma == std::string_view::npos) throw bad();
    SettingRange r;
    r.lo_open = text.front() == '(';
    r.hi_open = text.back() == ')';
    auto end = [&](std::string_view part, double& v, std::string& key) {
        bool ok = false;
        v = parse_number(part, ok);
        if (ok) return;
        if (part.empty() || !(std::isalpha(static_cast<unsigned char>(part.front())))) throw bad();
        key = std::string(part);
    };
    end(text.substr(1, comma - 1), r.lo, r.lo_key);
    end(text.substr(comma + 2, text.size() - comma - 3), r.hi, r.hi_key);
    return r;
}

std::string SettingRange::text() const
{
    return std::string(lo_open ? "(" : "[") + (lo_key.empty() ? number_text(lo) : lo_key) + ", " +
           (hi_key.empty() ? number_text(hi) : hi_key) + (hi_open ? ")" : "]");
}

bool SettingRange::contains(double v, double lo_value, double hi_value) const
{
    const double a = lo_key.empty() ? lo : lo_value, b = hi_key.empty() ? hi : hi_value;
    const bool above = std::isnan(a) || (lo_open ? v > a : v >= a);
    const bool below = std::isnan(b) || (hi_open ? v < b : v <= b);
    return std::isfinite(v) && above && below;
}

std::string SettingInfo::allowed() const
{
    switch (type) {
    case SettingType::Number:
    case SettingType::Integer: return range.text();
    case SettingType::Name: {
        if (choices.empty()) return "a name of 1 to " + std::to_string(kMaxNameLength) + " characters";
        std::string out;
        for (std::size_t i = 0; i < choices.size(); ++i)
            out += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + ("\"" + choices[i] + "\"");
        return out;
    }
    case SettingType::Color: return "r,g,b each in [0, 1]";
    case SettingType::Weights: return "up to " + std::to_string(kMaxWeights) + " name:weight in [0, 1e6]";
    }
    return {};
}

const std::vector<SettingInfo>& settings_table() { return table().infos; }
const std::vector<std::string>& settings_sections() { return table().sections; }

const SettingInfo* find_setting(std::string_view key)
{
    for (const SettingInfo& info : settings_table())
        if (info.key == key) return &info;
    return nullptr;
}

SettingValue get_setting(const Settings& s, const SettingInfo& info)
{
    return std::visit(
        [](auto p) -> SettingValue {
            using P = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
            if constexpr (std::is_same_v<P, const double[3]> || std::is_same_v<P, double[3]>)
                return std::array<double, 3>{(*p)[0], (*p)[1], (*p)[2]};
            else
                return *p;
        },
        access_of(info).cref(s));
}

void set_setting(Settings& s, const SettingInfo& info, const SettingValue& value)
{
    if (value.index() != static_cast<std::size_t>(info.type))
        throw InvalidInput(where(info) + ": a value of the wrong type");
    std::visit(
        [&](auto p) {
            using P = std::remove_pointer_t<decltype(p)>;
            if constexpr (std::is_same_v<P, double[3]>) {
                const auto& c = std::get<std::array<double, 3>>(value);
                for (std::size_t k = 0; k < 3; ++k) (*p)[k] = c[k];
            } else {
                *p = std::get<P>(value);
            }
        },
        access_of(info).ref(s));
}

void copy_setting(const Settings& from, Settings& to, const SettingInfo& info) { set_setting(to, info, get_setting(from, info)); }

std::string number_text(double v)
{
    if (!std::isfinite(v)) return std::isnan(v) ? "nan" : v < 0 ? "-inf" : "inf";
    char buf[400]; // the longest shortest fixed form of a double is 327 characters
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
    if (ec != std::errc()) throw std::logic_error("number_text: buffer too small");
    return std::string(buf, end);
}

std::string setting_text(const Settings& s, const SettingInfo& info)
{
    const SettingValue v = get_setting(s, info);
    switch (info.type) {
    case SettingType::Number: return number_text(std::get<double>(v));
    case SettingType::Integer: return std::to_string(std::get<int>(v));
    case SettingType::Name: return std::get<std::string>(v);
    case SettingType::Color: {
        const auto& c = std::get<std::array<double, 3>>(v);
        return number_text(c[0]) + "," + number_text(c[1]) + "," + number_text(c[2]);
    }
    case SettingType::Weights: {
        std::string out;
        for (const auto& [name, w] : std::get<Weights>(v)) out += (out.empty() ? "" : ",") + name + ":" + number_text(w);
        return out;
    }
    }
    return {};
}

void set_setting_text(Settings& s, const SettingInfo& info, std::string_view text)
{
    const std::string w = where(info);
    SettingValue value;
    bool ok = false;
    switch (info.type) {
    case SettingType::Number:
        value = parse_number(text, ok);
        if (!ok) throw InvalidInput(w + ": expected a number, not '" + std::string(text) + "'");
        break;
    case SettingType::Integer: {
        long long i = 0;
        const std::string_view digits = text.size() > 1 && text.front() == '+' && text[1] != '-' ? text.substr(1) : text;
        const char* end = digits.data() + digits.size();
        const auto [p, ec] = std::from_chars(digits.data(), end, i);
        if (ec != std::errc() || p != end || i < -1000000000LL || i > 1000000000LL)
            throw InvalidInput(w + ": expected an integer, not '" + std::string(text) + "'");
        value = static_cast<int>(i);
        break;
    }
    case SettingType::Name: value = std::string(text); break;
    case SettingType::Color: {
        const std::vector<std::string_view> parts = split_commas(text);
        std::array<double, 3> c{};
        ok = parts.size() == 3;
        for (std::size_t k = 0; ok && k < 3; ++k) c[k] = parse_number(parts[k], ok);
        if (!ok) throw InvalidInput(w + ": expected r,g,b (three numbers), not '" + std::string(text) + "'");
        value = c;
        break;
    }
    case SettingType::Weights: {
        Weights weights;
        for (std::string_view part : split_commas(text)) {
            const std::size_t colon = part.find(':');
            double v = 0.0;
            if (colon != std::string_view::npos) v = parse_number(part.substr(colon + 1), ok);
            if (colon == std::string_view::npos || colon == 0 || !ok)
                throw InvalidInput(w + ": expected name:weight,… (empty for none), not '" + std::string(text) + "'");
            weights[std::string(part.substr(0, colon))] = v;
        }
        value = std::move(weights);
        break;
    }
    }
    check_value(info, value, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN());
    set_setting(s, info, value);
}

void check_setting(const Settings& s, const SettingInfo& info)
{
    constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
    const double lo = info.range.lo_key.empty() ? kNone : keyed_end(s, info, info.range.lo_key);
    const double hi = info.range.hi_key.empty() ? kNone : keyed_end(s, info, info.range.hi_key);
    check_value(info, get_setting(s, info), lo, hi);
}

void validate_settings_section(const Settings& s, std::string_view section)
{
    for (const SettingInfo& info : settings_table())
        if (in_section(info.key, section)) check_setting(s, info);
}

void validate_settings(const Settings& s)
{
    for (const SettingInfo& info : settings_table()) check_setting(s, info);
}

bool settings_equal(const Settings& a, const Settings& b)
{
    for (const SettingInfo& info : settings_table())
        if (get_setting(a, info) != get_setting(b, info)) return false;
    return true;
}

std::string settings_key(const Settings& s, std::string_view section)
{
    std::string key;
    for (const SettingInfo& info : settings_table())
        if (in_section(info.key, section)) key += info.key + "=" + setting_text(s, info) + "\n";
    return key;
}

void SettingsOverlay::set_text(std::string_view key, std::string_view text)
{
    const SettingInfo* info = find_setting(key);
    if (!info) throw InvalidInput("unknown setting '" + std::string(key) + "' (`lobesketch settings` lists them)");
    set_setting_text(values, *info, text);
    mark(key);
}

void SettingsOverlay::mark(std::string_view key)
{
    if (!find_setting(key)) throw std::logic_error("SettingsOverlay::mark: no setting " + std::string(key));
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.emplace_back(key);
}

void SettingsOverlay::apply_to(Settings& s) const
{
    for (const std::string& key : keys) copy_setting(values, s, *find_setting(key));
}

} // namespace lobe
