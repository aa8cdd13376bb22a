// Reading cpfg's view files (`.v`) and loading a `.l` file with the view file beside it:
// lsystem.h.
#include <charconv>
#include <cmath>
#include <fstream>

#include "core/errors.h"
#include "growth/lsystem/expr.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/lsystem_text.h"

namespace lobe::lsystem {

namespace {

using detail::SourceText;
using detail::is_blank;
using detail::is_letter;
using detail::lower;
using detail::shorten;

/// Numbers separated by blanks or commas; false for anything else or a non-finite number.
bool parse_numbers(std::string_view s, std::vector<double>& out)
{
    std::size_t p = 0;
    while (p < s.size()) {
        while (p < s.size() && (is_blank(s[p]) || s[p] == ',')) ++p;
        if (p >= s.size()) break;
        double v = 0.0;
        const char* b = s.data() + p;
        if (*b == '+') ++b;
        const auto r = std::from_chars(b, s.data() + s.size(), v);
        if (r.ec != std::errc() || !std::isfinite(v)) return false;
        out.push_back(v);
        p = static_cast<std::size_t>(r.ptr - s.data());
        if (p < s.size() && !is_blank(s[p]) && s[p] != ',') return false;
    }
    return true;
}

/// A unit vector from three numbers. \throw InvalidInput (at `offset`) for a zero vector.
glm::dvec3 unit_direction(const std::vector<double>& d, const SourceText& src, std::size_t offset)
{
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(len > 0.0) || !std::isfinite(len)) src.fail(offset, "'tropism direction' must not be zero");
    return glm::dvec3(d[0], d[1], d[2]) / len;
}

/// cpfg 4's `tropism: T: x,y,z, A: angle, I: intensity, E: elasticity, S: step`: T and E are
/// read, the other fields skipped. `vb` is the value's offset in the source.
void read_tropism_fields(std::string_view s, std::size_t vb, const SourceText& src, ViewSettings& v)
{
    bool any = false;
    for (std::size_t k = 0; k + 1 < s.size(); ++k) {
        const char key = s[k];
        if (!((key == 'T' || key == 'E' || key == 'A' || key == 'I' || key == 'S') && s[k + 1] == ':')) continue;
        if (k > 0 && is_letter(s[k - 1])) continue;
        std::size_t stop = k + 2;
        while (stop < s.size()) {
            if (stop + 1 < s.size() && is_letter(s[stop]) && s[stop + 1] == ':') break;
            ++stop;
        }
        std::vector<double> vals;
        std::string_view field = s.substr(k + 2, stop - k - 2);
        while (!field.empty() && (is_blank(field.back()) || field.back() == ',')) field.remove_suffix(1);
        if (!parse_numbers(field, vals)) src.fail(vb + k, "malformed 'tropism' field '" + std::string(1, key) + ":'");
        if (key == 'T') {
            if (vals.size() != 3) src.fail(vb + k, "'tropism' T: needs x,y,z");
            v.tropism_direction = unit_direction(vals, src, vb + k);
            any = true;
        } else if (key == 'E') {
            if (vals.size() != 1) src.fail(vb + k, "'tropism' E: needs one value");
            v.elasticity = vals[0];
            any = true;
        }
        k = stop - 1;
    }
    if (!any) src.fail(vb, "a 'tropism:' line without T: or E:");
    v.tropism = true;
}

/// The label of a `label: value` line, lower case, inner blanks single; empty without ':'.
std::string view_label(std::string_view clean, std::size_t p, std::size_t colon)
{
    std::string label;
    for (std::size_t k = p; k < colon; ++k) {
        const char c = lower(clean[k]);
        if (is_blank(c)) {
            if (!label.empty() && label.back() != ' ') label += ' ';
        } else {
            label += c;
        }
    }
    while (!label.empty() && label.back() == ' ') label.pop_back();
    return label;
}

/// One non-blank line [p, end) of a view file into `v`; a line it does not use is a warning.
void read_view_line(std::string_view clean, std::size_t p, std::size_t end, const SourceText& src,
                    detail::Warnings& warn, ViewSettings& v)
{
    const std::size_t colon = clean.find(':', p);
    const std::string label = colon != std::string::npos && colon < end ? view_label(clean, p, colon) : std::string();
    const std::size_t vb = colon == std::string::npos ? end : colon + 1;
    const std::string_view value = clean.substr(vb, end > vb ? end - vb : 0);
    auto numbers = [&](std::size_t count, bool allow_unit) {
        std::vector<double> out;
        std::string_view s = value;
        if (allow_unit) {
            // `initial line width: 2 pixels` / `polygons`
            std::size_t k = s.size();
            while (k > 0 && is_letter(s[k - 1])) --k;
            s = s.substr(0, k);
        }
        if (!parse_numbers(s, out) || out.size() != count)
            src.fail(vb, "malformed value for '" + label + "': '" + shorten(value) + "'");
        return out;
    };
    if (label == "angle increment") {
        v.angle_increment_deg = numbers(1, false)[0];
    } else if (label == "angle factor") {
        const double f = numbers(1, false)[0];
        if (f == 0.0) src.fail(vb, "'angle factor' must not be 0");
        v.angle_increment_deg = 360.0 / f;
    } else if (label == "initial line width") {
        v.initial_line_width = numbers(1, true)[0];
        std::size_t k = value.size();
        while (k > 0 && is_letter(value[k - 1])) --k;
        std::string unit;
        for (const char c : value.substr(k)) unit += lower(c);
        if (unit == "polygons" || unit == "polygon") v.width_unit = ViewSettings::WidthUnit::Model;
        else if (unit.empty() || unit == "pixels" || unit == "pixel") v.width_unit = ViewSettings::WidthUnit::Pixels;
        else src.fail(vb + k, "a line width is in 'pixels' or 'polygons', not '" + shorten(unit) + "'");
    } else if (label == "line style") {
        std::string style;
        for (const char c : value)
            if (!is_blank(c)) style += lower(c);
        if (style == "pixel" || style == "pixels") v.width_unit = ViewSettings::WidthUnit::Pixels;
        else if (style == "polygon" || style == "polygons" || style == "cylinder" || style == "cylinders")
            v.width_unit = ViewSettings::WidthUnit::Model;
        else src.fail(vb, "'line style' is pixel, polygon or cylinder, not '" + shorten(value) + "'");
    } else if (label == "line width increment") {
        v.line_width_increment = numbers(1, false)[0];
    } else if (label == "scale factor") {
        v.scale_factor = numbers(1, false)[0];
    } else if (label == "metres per unit") {
        const double m = numbers(1, false)[0];
        if (!(m > 0.0 && m <= 1000.0)) src.fail(vb, "'metres per unit' must be a number in (0, 1000]");
        v.metres_per_unit = m;
    } else if (label == "tropism direction") {
        v.tropism_direction = unit_direction(numbers(3, false), src, vb);
        v.tropism = true;
    } else if (label == "initial elasticity" || label == "elasticity") {
        v.elasticity = numbers(1, false)[0];
        v.tropism = true;
    } else if (label == "elasticity increment") {
        v.elasticity_increment = numbers(1, false)[0];
    } else if (label == "tropism") {
        read_tropism_fields(value, vb, src, v);
    } else {
        const std::string shown = label.empty() ? shorten(clean.substr(p, end - p)) : label;
        warn.add(src.where(p) + "view line '" + shown + "' is not used; skipped");
    }
}

/// The whole file, refusing one over kMaxFileBytes before reading it.
std::string read_source_file(const std::filesystem::path& p)
{
    std::error_code ec;
    const auto size = std::filesystem::file_size(p, ec);
    if (ec) throw FileError(p.string(), "cannot read: " + ec.message());
    if (size > kMaxFileBytes)
        throw InvalidInput(p.string() + ":1:1: the file is " + std::to_string(size) + " bytes, over the limit of " +
                           std::to_string(kMaxFileBytes) + " bytes");
    std::ifstream in(p, std::ios::binary);
    if (!in) throw FileError(p.string(), "cannot open");
    std::string text;
    text.resize(static_cast<std::size_t>(size));
    in.read(text.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::size_t>(in.gcount()) != size) throw FileError(p.string(), "cannot read the whole file");
    return text;
}

} // namespace

ViewSettings parse_view(std::string_view text, const std::string& source_name, std::vector<std::string>* warnings)
{
    SourceText raw(text, source_name);
    if (text.size() > kMaxFileBytes)
        raw.fail(0, "the file is " + std::to_string(text.size()) + " bytes, over the limit of " + std::to_string(kMaxFileBytes) + " bytes");
    const std::string clean = detail::blank_comments(text, raw);
    const SourceText src(clean, source_name);
    detail::Warnings warn(warnings);
    ViewSettings v;
    std::size_t b = 0;
    while (b <= clean.size()) {
        std::size_t e = clean.find('\n', b);
        if (e == std::string::npos) e = clean.size();
        std::size_t p = b;
        while (p < e && is_blank(clean[p])) ++p;
        std::size_t end = e;
        while (end > p && is_blank(clean[end - 1])) --end;
        if (p < end) read_view_line(clean, p, end, src, warn, v);
        if (e >= clean.size()) break;
        b = e + 1;
    }
    warn.finish(source_name);
    return v;
}

LSystemFile load_lsystem_file(const std::filesystem::path& path)
{
    LSystemFile f;
    const std::string text = read_source_file(path);
    f.system = parse_lsystem(text, path.string(), &f.warnings);
    std::filesystem::path view = path;
    view.replace_extension(".v");
    std::error_code ec;
    if (view != path && std::filesystem::is_regular_file(view, ec)) {
        const std::string vtext = read_source_file(view);
        f.view = parse_view(vtext, view.string(), &f.warnings);
        f.has_view = true;
    }
    return f;
}

} // namespace lobe::lsystem
