#include "meshing/mesh_io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string_view>
#include <vector>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace lobe {

namespace {

using Limits = MeshIoLimits;

// ---------------------------------------------------------------------------------------
// Shared helpers
// ---------------------------------------------------------------------------------------

/// A short, printable, single-line excerpt of file content for error messages.
std::string excerpt(std::string_view s)
{
    std::string out;
    for (char c : s.substr(0, 32)) out += (c >= 32 && c < 127) ? c : '?';
    if (s.size() > 32) out += "...";
    return out;
}

std::string line_prefix(std::size_t line) { return "line " + std::to_string(line) + ": "; }

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Splits a line into whitespace-separated tokens.
void split_tokens(std::string_view line, std::vector<std::string_view>& tokens)
{
    tokens.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_space(line[i])) ++i;
        const std::size_t b = i;
        while (i < line.size() && !is_space(line[i])) ++i;
        if (i > b) tokens.push_back(line.substr(b, i - b));
    }
}

bool parse_double(std::string_view s, double& out)
{
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if (s.empty()) return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool parse_int(std::string_view s, long long& out)
{
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    if (s.empty()) return false;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

/// Iterates over the lines of a buffer, counting them from 1.
class LineReader {
public:
    explicit LineReader(std::string_view data, std::size_t start = 0, std::size_t first_line = 1)
        : data_(data), pos_(start), line_(first_line - 1) {}

    bool next(std::string_view& line)
    {
        if (pos_ >= data_.size()) return false;
        const std::size_t end = data_.find('\n', pos_);
        const std::size_t stop = end == std::string_view::npos ? data_.size() : end;
        line = data_.substr(pos_, stop - pos_);
        pos_ = end == std::string_view::npos ? data_.size() : end + 1;
        ++line_;
        return true;
    }
    std::size_t line() const { return line_; }
    std::size_t position() const { return pos_; } ///< offset of the next line

private:
    std::string_view data_;
    std::size_t pos_;
    std::size_t line_;
};

/// Collects vertices and triangles with the caps of MeshIoLimits.
class MeshBuilder {
public:
    explicit MeshBuilder(const std::string& path) : path_(path) {}

    void reserve(std::size_t vertices, std::size_t triangles)
    {
        mesh_.positions.reserve(vertices);
        mesh_.triangles.reserve(triangles);
    }

    void add_vertex(double x, double y, double z, const std::string& where)
    {
        if (mesh_.positions.size() >= Limits::max_vertices)
            fail(where + "more than " + std::to_string(Limits::max_vertices) + " vertices");
        const glm::vec3 p(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            fail(where + "vertex " + std::to_string(mesh_.positions.size()) +
                 " has a non-finite coordinate (NaN, infinite or beyond float range)");
        mesh_.positions.push_back(p);
    }

    /// Adds a polygon (0-based indices, already range-checked) as a triangle fan.
    void add_polygon(const std::vector<int>& poly, const std::string& where)
    {
        if (poly.size() < 3)
            fail(where + "face with " + std::to_string(poly.size()) + " vertices (at least 3 needed)");
        if (mesh_.triangles.size() + (poly.size() - 2) > Limits::max_triangles)
            fail(where + "more than " + std::to_string(Limits::max_triangles) + " triangles");
        for (std::size_t i = 1; i + 1 < poly.size(); ++i) mesh_.triangles.push_back({poly[0], poly[i], poly[i + 1]});
    }

    void add_polyline(const std::vector<int>& line)
    {
        for (std::size_t i = 0; i + 1 < line.size(); ++i)
            if (line[i] != line[i + 1]) mesh_.feature_edges.push_back({line[i], line[i + 1]});
    }

    std::size_t vertex_count() const { return mesh_.positions.size(); }

    /// Range check of a 0-based index.
    int index(long long i, const std::string& where) const
    {
        if (i < 0 || i >= static_cast<long long>(mesh_.positions.size()))
            fail(where + "vertex index " + std::to_string(i) + " out of range (" +
                 std::to_string(mesh_.positions.size()) + " vertices)");
        return static_cast<int>(i);
    }

    TriangleMesh finish()
    {
        if (mesh_.positions.empty()) fail("no vertices");
        if (mesh_.triangles.empty()) fail("no faces");
        // Feature edges may be declared before all vertices exist (PLY edge element order).
        for (const auto& e : mesh_.feature_edges)
            for (int v : e)
                if (v < 0 || v >= static_cast<int>(mesh_.positions.size()))
                    fail("edge vertex index " + std::to_string(v) + " out of range");
        return std::move(mesh_);
    }

    [[noreturn]] void fail(const std::string& what) const { throw FileError(path_, what); }

private:
    const std::string& path_;
    TriangleMesh mesh_;
};

// ---------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------

TriangleMesh read_obj(const std::string& path, std::string_view data)
{
    MeshBuilder mb(path);
    LineReader lines(data);
    std::string_view line;
    std::vector<std::string_view> tok;
    std::vector<int> poly;
    while (lines.next(line)) {
        const std::size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
        split_tokens(line, tok);
        if (tok.empty()) continue;
        const std::string where = line_prefix(lines.line());
        if (tok[0] == "v") {
            if (tok.size() < 4) mb.fail(where + "vertex with fewer than 3 coordinates");
            double c[3];
            for (int k = 0; k < 3; ++k)
                if (!parse_double(tok[static_cast<std::size_t>(k) + 1], c[k]))
                    mb.fail(where + "bad coordinate '" + excerpt(tok[static_cast<std::size_t>(k) + 1]) + "'");
            mb.add_vertex(c[0], c[1], c[2], where);
        } else if (tok[0] == "f" || tok[0] == "l") {
            poly.clear();
            for (std::size_t k = 1; k < tok.size(); ++k) {
                // i, i/t, i//n, i/t/n: only the first number matters here.
                std::string_view ref = tok[k];
                ref = ref.substr(0, ref.find('/'));
                long long i = 0;
                if (!parse_int(ref, i)) mb.fail(where + "bad vertex reference '" + excerpt(tok[k]) + "'");
                if (i == 0) mb.fail(where + "vertex index 0 (OBJ indices start at 1)");
                const long long n = static_cast<long long>(mb.vertex_count());
                const long long zero_based = i > 0 ? i - 1 : n + i;
                if (zero_based < 0 || zero_based >= n)
                    mb.fail(where + "vertex index " + std::to_string(i) + " out of range (" + std::to_string(n) +
                            " vertices defined so far)");
                poly.push_back(static_cast<int>(zero_based));
                if (poly.size() > Limits::max_triangles) mb.fail(where + "face with too many vertices");
            }
            if (tok[0] == "f") {
                mb.add_polygon(poly, where);
            } else {
                if (poly.size() < 2) mb.fail(where + "line element with fewer than 2 vertices");
                mb.add_polyline(poly);
            }
        }
        // vt, vn, o, g, s, usemtl, mtllib and anything else: not geometry we use.
    }
    return mb.finish();
}

// ---------------------------------------------------------------------------------------
// OFF
// ---------------------------------------------------------------------------------------

TriangleMesh read_off(const std::string& path, std::string_view data)
{
    MeshBuilder mb(path);
    LineReader lines(data);
    std::string_view line;
    std::vector<std::string_view> tok;

    // Next non-empty, non-comment line as tokens; false at the end of the file.
    auto next_tokens = [&]() {
        while (lines.next(line)) {
            const std::size_t hash = line.find('#');
            if (hash != std::string_view::npos) line = line.substr(0, hash);
            split_tokens(line, tok);
            if (!tok.empty()) return true;
        }
        return false;
    };

    if (!next_tokens()) mb.fail("empty file");
    const std::string_view magic = tok[0];
    if (magic.size() < 3 || magic.substr(magic.size() - 3) != "OFF")
        mb.fail("line 1: not an OFF file (header '" + excerpt(magic) + "')");
    if (magic.find('n') != std::string_view::npos || magic.find('4') != std::string_view::npos)
        mb.fail("line 1: only 3D OFF is supported (header '" + excerpt(magic) + "')");
    std::size_t counts_at = 1;
    if (tok.size() > 1 && tok[1] == "BINARY") mb.fail("line 1: binary OFF is not supported");
    if (tok.size() == 1) {
        if (!next_tokens()) mb.fail("missing vertex and face counts");
        counts_at = 0;
    }
    if (tok.size() < counts_at + 2) mb.fail(line_prefix(lines.line()) + "missing vertex and face counts");
    long long nv = 0, nf = 0;
    if (!parse_int(tok[counts_at], nv) || !parse_int(tok[counts_at + 1], nf) || nv < 0 || nf < 0)
        mb.fail(line_prefix(lines.line()) + "bad vertex or face count");
    if (static_cast<unsigned long long>(nv) > Limits::max_vertices)
        mb.fail(line_prefix(lines.line()) + "declares " + std::to_string(nv) + " vertices (limit " +
                std::to_string(Limits::max_vertices) + ")");
    if (static_cast<unsigned long long>(nf) > Limits::max_triangles)
        mb.fail(line_prefix(lines.line()) + "declares " + std::to_string(nf) + " faces (limit " +
                std::to_string(Limits::max_triangles) + ")");
    // Each vertex line holds at least "x y z\n" (6 bytes), each face "3 a b c\n" (8 bytes).
    if (static_cast<unsigned long long>(nv) * 6 + static_cast<unsigned long long>(nf) * 8 > data.size())
        mb.fail(line_prefix(lines.line()) + "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                " faces, more than the file's " + std::to_string(data.size()) + " bytes can hold");
    mb.reserve(static_cast<std::size_t>(nv), static_cast<std::size_t>(nf));

    for (long long i = 0; i < nv; ++i) {
        if (!next_tokens()) mb.fail("truncated: " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
        const std::string where = line_prefix(lines.line());
        if (tok.size() < 3) mb.fail(where + "vertex with fewer than 3 coordinates");
        double c[3];
        for (std::size_t k = 0; k < 3; ++k)
            if (!parse_double(tok[k], c[k])) mb.fail(where + "bad coordinate '" + excerpt(tok[k]) + "'");
        mb.add_vertex(c[0], c[1], c[2], where);
    }
    std::vector<int> poly;
    for (long long i = 0; i < nf; ++i) {
        if (!next_tokens()) mb.fail("truncated: " + std::to_string(i) + " of " + std::to_string(nf) + " faces");
        const std::string where = line_prefix(lines.line());
        long long n = 0;
        if (!parse_int(tok[0], n) || n < 0) mb.fail(where + "bad face size '" + excerpt(tok[0]) + "'");
        if (static_cast<unsigned long long>(n) + 1 > tok.size())
            mb.fail(where + "face declares " + std::to_string(n) + " vertices but lists fewer");
        poly.clear();
        for (std::size_t k = 1; k <= static_cast<std::size_t>(n); ++k) {
            long long v = 0;
            if (!parse_int(tok[k], v)) mb.fail(where + "bad vertex index '" + excerpt(tok[k]) + "'");
            poly.push_back(mb.index(v, where));
        }
        mb.add_polygon(poly, where);
    }
    return mb.finish();
}

// ---------------------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------------------

enum class PlyType { none, i8, u8, i16, u16, i32, u32, f32, f64 };

PlyType ply_type(std::string_view s)
{
    if (s == "char" || s == "int8") return PlyType::i8;
    if (s == "uchar" || s == "uint8") return PlyType::u8;
    if (s == "short" || s == "int16") return PlyType::i16;
    if (s == "ushort" || s == "uint16") return PlyType::u16;
    if (s == "int" || s == "int32") return PlyType::i32;
    if (s == "uint" || s == "uint32") return PlyType::u32;
    if (s == "float" || s == "float32") return PlyType::f32;
    if (s == "double" || s == "float64") return PlyType::f64;
    return PlyType::none;
}

std::size_t ply_size(PlyType t)
{
    switch (t) {
    case PlyType::i8:
    case PlyType::u8: return 1;
    case PlyType::i16:
    case PlyType::u16: return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32: return 4;
    case PlyType::f64: return 8;
    case PlyType::none: break;
    }
    return 0;
}

bool ply_is_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64; }

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::none;       ///< value type (item type for lists)
    PlyType count_type = PlyType::none; ///< none: a scalar property
};

struct PlyElement {
    std::string name;
    unsigned long long count = 0;
    std::vector<PlyProperty> properties;
};

enum class PlyFormat { ascii, binary_le, binary_be };

/// Reads the values of a PLY body one at a time, binary or ASCII, with bounds checks.
class PlyBody {
public:
    PlyBody(MeshBuilder& mb, std::string_view data, std::size_t start, PlyFormat format, std::size_t first_line)
        : mb_(mb), data_(data), pos_(start), format_(format), line_(first_line) {}

    /// One value as double; `what` names it for error messages.
    double value(PlyType t, const std::string& what)
    {
        if (format_ == PlyFormat::ascii) return ascii_value(t, what);
        const std::size_t n = ply_size(t);
        if (data_.size() - pos_ < n) mb_.fail("truncated binary data in " + what);
        unsigned char b[8];
        std::memcpy(b, data_.data() + pos_, n);
        pos_ += n;
        const bool file_le = format_ == PlyFormat::binary_le;
        if (file_le != (std::endian::native == std::endian::little)) std::reverse(b, b + n);
        switch (t) {
        case PlyType::i8: return static_cast<double>(static_cast<std::int8_t>(b[0]));
        case PlyType::u8: return static_cast<double>(b[0]);
        case PlyType::i16: return static_cast<double>(load<std::int16_t>(b));
        case PlyType::u16: return static_cast<double>(load<std::uint16_t>(b));
        case PlyType::i32: return static_cast<double>(load<std::int32_t>(b));
        case PlyType::u32: return static_cast<double>(load<std::uint32_t>(b));
        case PlyType::f32: return static_cast<double>(load<float>(b));
        case PlyType::f64: return load<double>(b);
        case PlyType::none: break;
        }
        return 0.0;
    }

    /// Skips `n` values of type t (a list's items in an element we do not use).
    void skip(PlyType t, unsigned long long n, const std::string& what)
    {
        if (format_ == PlyFormat::ascii) {
            for (unsigned long long i = 0; i < n; ++i) ascii_value(t, what);
            return;
        }
        const unsigned long long bytes = n * ply_size(t);
        if (n > data_.size() || bytes > data_.size() - pos_) mb_.fail("truncated binary data in " + what);
        pos_ += static_cast<std::size_t>(bytes);
    }

    std::string where() const { return format_ == PlyFormat::ascii ? line_prefix(line_) : std::string(); }

private:
    template <class T>
    static T load(const unsigned char* b)
    {
        T v;
        std::memcpy(&v, b, sizeof(T));
        return v;
    }

    double ascii_value(PlyType t, const std::string& what)
    {
        while (pos_ < data_.size() && (is_space(data_[pos_]) || data_[pos_] == '\n')) {
            if (data_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ >= data_.size()) mb_.fail("truncated: end of file in " + what);
        const std::size_t b = pos_;
        while (pos_ < data_.size() && !is_space(data_[pos_]) && data_[pos_] != '\n') ++pos_;
        const std::string_view s = data_.substr(b, pos_ - b);
        if (ply_is_integer(t)) {
            long long i = 0;
            if (!parse_int(s, i)) mb_.fail(line_prefix(line_) + "bad integer '" + excerpt(s) + "' in " + what);
            return static_cast<double>(i);
        }
        double d = 0;
        if (!parse_double(s, d)) mb_.fail(line_prefix(line_) + "bad number '" + excerpt(s) + "' in " + what);
        return d;
    }

    MeshBuilder& mb_;
    std::string_view data_;
    std::size_t pos_;
    PlyFormat format_;
    std::size_t line_;
};

/// A PLY header: the body's format and its elements in order.
struct PlyHeader {
    PlyFormat format = PlyFormat::ascii;
    std::vector<PlyElement> elements;
};

/// Reads the header, `lines` left right after its end_header line.
PlyHeader read_ply_header(const MeshBuilder& mb, LineReader& lines)
{
    std::string_view line;
    std::vector<std::string_view> tok;
    PlyHeader header;
    PlyFormat& format = header.format;
    std::vector<PlyElement>& elements = header.elements;
    if (!lines.next(line) || (line != "ply" && line != "ply\r")) mb.fail("not a PLY file (missing 'ply' magic)");
    bool have_format = false, ended = false;
    while (!ended && lines.next(line)) {
        split_tokens(line, tok);
        const std::string where = line_prefix(lines.line());
        if (tok.empty()) continue;
        if (tok[0] == "comment" || tok[0] == "obj_info") continue;
        if (tok[0] == "end_header") {
            ended = true;
        } else if (tok[0] == "format") {
            if (tok.size() < 3 || tok[2] != "1.0") mb.fail(where + "bad format line");
            if (tok[1] == "ascii") format = PlyFormat::ascii;
            else if (tok[1] == "binary_little_endian") format = PlyFormat::binary_le;
            else if (tok[1] == "binary_big_endian") format = PlyFormat::binary_be;
            else mb.fail(where + "unknown format '" + excerpt(tok[1]) + "'");
            have_format = true;
        } else if (tok[0] == "element") {
            if (tok.size() != 3) mb.fail(where + "bad element line");
            long long n = 0;
            if (!parse_int(tok[2], n) || n < 0) mb.fail(where + "bad element count '" + excerpt(tok[2]) + "'");
            if (elements.size() >= 64) mb.fail(where + "too many elements");
            elements.push_back({std::string(tok[1]), static_cast<unsigned long long>(n), {}});
        } else if (tok[0] == "property") {
            if (elements.empty()) mb.fail(where + "property before any element");
            PlyProperty p;
            if (tok.size() == 5 && tok[1] == "list") {
                p.count_type = ply_type(tok[2]);
                p.type = ply_type(tok[3]);
                p.name = std::string(tok[4]);
                if (p.count_type == PlyType::none || p.type == PlyType::none || !ply_is_integer(p.count_type))
                    mb.fail(where + "bad list property types");
            } else if (tok.size() == 3) {
                p.type = ply_type(tok[1]);
                p.name = std::string(tok[2]);
                if (p.type == PlyType::none) mb.fail(where + "unknown property type '" + excerpt(tok[1]) + "'");
            } else {
                mb.fail(where + "bad property line");
            }
            if (elements.back().properties.size() >= 256) mb.fail(where + "too many properties");
            elements.back().properties.push_back(std::move(p));
        } else {
            mb.fail(where + "unknown header keyword '" + excerpt(tok[0]) + "'");
        }
    }
    if (!ended) mb.fail("header has no end_header");
    if (!have_format) mb.fail("header has no format line");
    return header;
}

/// The vertex and the face element. Checks the declared counts against the caps and against
/// what the body (`body_bytes`) can hold, before anything is allocated.
std::pair<const PlyElement*, const PlyElement*> check_ply_counts(const MeshBuilder& mb, const PlyHeader& header,
                                                                 std::size_t body_bytes)
{
    const PlyFormat format = header.format;
    // Binary: a scalar takes its size, a list at least its count (a face list at least
    // count + 3 indices). ASCII: every value takes at least 2 bytes.
    const PlyElement* vertex_el = nullptr;
    const PlyElement* face_el = nullptr;
    unsigned long long min_bytes = 0;
    for (const PlyElement& el : header.elements) {
        if (el.name == "vertex") vertex_el = &el;
        if (el.name == "face") face_el = &el;
        unsigned long long per = 0;
        for (const PlyProperty& p : el.properties) {
            const bool face_list = el.name == "face" && p.count_type != PlyType::none;
            if (format == PlyFormat::ascii) per += face_list ? 8 : 2;
            else if (p.count_type == PlyType::none) per += ply_size(p.type);
            else per += ply_size(p.count_type) + (face_list ? 3 * ply_size(p.type) : 0);
        }
        per = std::max<unsigned long long>(per, 1);
        if (el.count > body_bytes / per)
            mb.fail("element '" + excerpt(el.name) + "' declares " + std::to_string(el.count) +
                    " entries, more than the file's " + std::to_string(body_bytes) + " bytes of data can hold");
        min_bytes += el.count * per;
    }
    if (min_bytes > body_bytes)
        mb.fail("header declares more data than the file's " + std::to_string(body_bytes) + " bytes hold");
    if (!vertex_el) mb.fail("no vertex element");
    if (!face_el) mb.fail("no face element");
    if (vertex_el->count > Limits::max_vertices)
        mb.fail("declares " + std::to_string(vertex_el->count) + " vertices (limit " +
                std::to_string(Limits::max_vertices) + ")");
    if (face_el->count > Limits::max_triangles)
        mb.fail("declares " + std::to_string(face_el->count) + " faces (limit " +
                std::to_string(Limits::max_triangles) + ")");
    return {vertex_el, face_el};
}

/// Where a PLY vertex's x, y and z and a face's index list are among their element's
/// properties.
struct PlyColumns {
    int xyz[3] = {-1, -1, -1};
    int face_list = -1;
};

PlyColumns find_ply_columns(const MeshBuilder& mb, const PlyElement& vertex, const PlyElement& face)
{
    PlyColumns columns;
    int (&xyz)[3] = columns.xyz;
    int& face_list = columns.face_list;
    for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
        const PlyProperty& p = vertex.properties[i];
        for (int k = 0; k < 3; ++k)
            if (p.name == std::string(1, static_cast<char>('x' + k)) && p.count_type == PlyType::none)
                xyz[k] = static_cast<int>(i);
    }
    if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) mb.fail("vertex element lacks scalar x, y, z properties");
    for (std::size_t i = 0; i < face.properties.size(); ++i) {
        const PlyProperty& p = face.properties[i];
        if ((p.name == "vertex_indices" || p.name == "vertex_index") && p.count_type != PlyType::none) {
            if (!ply_is_integer(p.type)) mb.fail("face indices are not integers");
            face_list = static_cast<int>(i);
        }
    }
    if (face_list < 0) mb.fail("face element lacks a vertex_indices list");
    return columns;
}

/// Reads every element of the body: the vertices and faces into `mb`, and "edge" elements as
/// polylines.
void read_ply_body(MeshBuilder& mb, PlyBody& in, const PlyHeader& header, const PlyElement* vertex_el,
                   const PlyElement* face_el, const PlyColumns& columns)
{
    const int (&xyz)[3] = columns.xyz;
    const int face_list = columns.face_list;
    std::vector<int> poly;
    std::vector<int> edge_ends;
    const std::size_t max_poly = 1u << 16;
    for (const PlyElement& el : header.elements) {
        const bool is_vertex = &el == vertex_el, is_face = &el == face_el, is_edge = el.name == "edge";
        for (unsigned long long e = 0; e < el.count; ++e) {
            const std::string what = "element '" + excerpt(el.name) + "' #" + std::to_string(e);
            double xyz_value[3] = {0, 0, 0};
            long long edge_v[2] = {-1, -1};
            poly.clear();
            for (std::size_t pi = 0; pi < el.properties.size(); ++pi) {
                const PlyProperty& p = el.properties[pi];
                if (p.count_type == PlyType::none) {
                    const double v = in.value(p.type, what);
                    for (int k = 0; k < 3; ++k)
                        if (is_vertex && xyz[k] == static_cast<int>(pi)) xyz_value[k] = v;
                    if (is_edge && ply_is_integer(p.type) && p.name == "vertex1") edge_v[0] = static_cast<long long>(v);
                    if (is_edge && ply_is_integer(p.type) && p.name == "vertex2") edge_v[1] = static_cast<long long>(v);
                    continue;
                }
                const double count_d = in.value(p.count_type, what);
                if (count_d < 0) mb.fail(in.where() + "negative list length in " + what);
                const auto count = static_cast<unsigned long long>(count_d);
                if (is_face && static_cast<int>(pi) == face_list) {
                    if (count < 3) mb.fail(in.where() + "face with " + std::to_string(count) + " vertices in " + what);
                    if (count > max_poly) mb.fail(in.where() + "face with too many vertices in " + what);
                    const std::string w = in.where();
                    for (unsigned long long k = 0; k < count; ++k) {
                        const double v = in.value(p.type, what);
                        poly.push_back(mb.index(static_cast<long long>(v), w + what + ": "));
                    }
                } else {
                    in.skip(p.type, count, what);
                }
            }
            if (is_vertex) mb.add_vertex(xyz_value[0], xyz_value[1], xyz_value[2], in.where());
            if (is_face) mb.add_polygon(poly, in.where());
            if (is_edge && edge_v[0] >= 0 && edge_v[1] >= 0) {
                if (edge_v[0] > std::numeric_limits<int>::max() || edge_v[1] > std::numeric_limits<int>::max())
                    mb.fail(what + ": vertex index out of range");
                edge_ends.push_back(static_cast<int>(edge_v[0]));
                edge_ends.push_back(static_cast<int>(edge_v[1]));
            }
        }
    }
    for (std::size_t i = 0; i + 1 < edge_ends.size(); i += 2) mb.add_polyline({edge_ends[i], edge_ends[i + 1]});
}

TriangleMesh read_ply(const std::string& path, std::string_view data)
{
    MeshBuilder mb(path);
    LineReader lines(data);
    const PlyHeader header = read_ply_header(mb, lines);
    const std::size_t body = lines.position(); // right after the end_header line
    const auto [vertex_el, face_el] = check_ply_counts(mb, header, data.size() - body);
    const PlyColumns columns = find_ply_columns(mb, *vertex_el, *face_el);
    mb.reserve(static_cast<std::size_t>(vertex_el->count), static_cast<std::size_t>(face_el->count));
    PlyBody in(mb, data, body, header.format, lines.line() + 1);
    read_ply_body(mb, in, header, vertex_el, face_el, columns);
    return mb.finish();
}

// ---------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------

void check_indices(const std::string& path, const TriangleMesh& mesh)
{
    const auto n = static_cast<long long>(mesh.positions.size());
    for (const auto& t : mesh.triangles)
        for (int v : t)
            if (v < 0 || v >= n) throw InvalidInput(path + ": cannot write: triangle index out of range");
    for (const auto& e : mesh.feature_edges)
        for (int v : e)
            if (v < 0 || v >= n) throw InvalidInput(path + ": cannot write: feature edge index out of range");
}

template <class T>
void append_le(std::string& out, T v)
{
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
    out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

std::string lower_extension(const std::string& path)
{
    const std::size_t dot = path.find_last_of('.');
    const std::size_t slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
    std::string ext = path.substr(dot + 1);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

} // namespace

TriangleMesh read_mesh(const std::string& path)
{
    return parse_mesh(read_file_limited(path, Limits::max_file_bytes), path);
}

TriangleMesh parse_mesh(const std::string& data, const std::string& path)
{
    if (data.size() > Limits::max_file_bytes)
        throw FileError(path, "file too large (" + std::to_string(data.size()) + " bytes, limit " +
                                  std::to_string(Limits::max_file_bytes) + ")");
    if (data.empty()) throw FileError(path, "empty file");
    std::string ext = lower_extension(path);
    if (ext != "obj" && ext != "ply" && ext != "off") {
        // Sniff: PLY and OFF start with a magic word; anything else is tried as OBJ.
        if (data.rfind("ply", 0) == 0) ext = "ply";
        else if (data.find("OFF") < 8) ext = "off";
        else ext = "obj";
    }
    if (ext == "ply") return read_ply(path, data);
    if (ext == "off") return read_off(path, data);
    return read_obj(path, data);
}

void write_ply(const std::string& path, const TriangleMesh& mesh)
{
    check_indices(path, mesh);
    std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by Lobesketch\n";
    out += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
    out += "property float x\nproperty float y\nproperty float z\n";
    out += "element face " + std::to_string(mesh.triangles.size()) + "\n";
    out += "property list uchar int vertex_indices\n";
    if (!mesh.feature_edges.empty()) {
        out += "element edge " + std::to_string(mesh.feature_edges.size()) + "\n";
        out += "property int vertex1\nproperty int vertex2\n";
    }
    out += "end_header\n";
    out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * 13 + mesh.feature_edges.size() * 8);
    for (const glm::vec3& p : mesh.positions) {
        append_le(out, p.x);
        append_le(out, p.y);
        append_le(out, p.z);
    }
    for (const auto& t : mesh.triangles) {
        append_le(out, std::uint8_t{3});
        for (int v : t) append_le(out, static_cast<std::int32_t>(v));
    }
    for (const auto& e : mesh.feature_edges)
        for (int v : e) append_le(out, static_cast<std::int32_t>(v));
    write_file_atomic(path, out);
}

void write_obj(const std::string& path, const TriangleMesh& mesh)
{
    check_indices(path, mesh);
    std::string out = "# written by Lobesketch\n";
    out.reserve(mesh.positions.size() * 40 + mesh.triangles.size() * 24);
    char buf[128];
    for (const glm::vec3& p : mesh.positions) {
        const int n = std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", static_cast<double>(p.x),
                                    static_cast<double>(p.y), static_cast<double>(p.z));
        out.append(buf, static_cast<std::size_t>(n));
    }
    for (const auto& t : mesh.triangles) {
        const int n = std::snprintf(buf, sizeof buf, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
        out.append(buf, static_cast<std::size_t>(n));
    }
    for (const auto& e : mesh.feature_edges) {
        const int n = std::snprintf(buf, sizeof buf, "l %d %d\n", e[0] + 1, e[1] + 1);
        out.append(buf, static_cast<std::size_t>(n));
    }
    write_file_atomic(path, out);
}

} // namespace lobe
