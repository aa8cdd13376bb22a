#include "app/export/export_obj.h"

#include <charconv>
#include <filesystem>
#include <string_view>

#include "core/atomic_file.h"

namespace lobe {

namespace {

/// Shortest text that reads back as the same float; independent of the C locale.
void put(std::string& out, float v)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

void put(std::string& out, std::size_t v)
{
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

// One "v x y z" (or "vn …") line per vector.
void put_vec3_lines(std::string& out, const char* key, const std::vector<glm::vec3>& vectors)
{
    for (const glm::vec3& p : vectors) {
        out += key;
        put(out, p.x);
        out += ' ';
        put(out, p.y);
        out += ' ';
        put(out, p.z);
        out += '\n';
    }
}

void put_rgb(std::string& out, const char* key, const std::array<float, 3>& c)
{
    out += key;
    for (float v : c) {
        out += ' ';
        put(out, v);
    }
    out += '\n';
}

std::string build_mtl(const PreparedExport& e, const std::string& png_name, const std::string& bark_png_name)
{
    std::string m = "# Lobesketch: materials of " + e.name + "\n";
    if (e.has_branches()) {
        m += "\nnewmtl bark\n";
        put_rgb(m, "Ka", {0.0f, 0.0f, 0.0f});
        put_rgb(m, "Kd", e.bark_color);
        put_rgb(m, "Ks", {0.0f, 0.0f, 0.0f});
        m += "d 1\nillum 1\n";
        if (e.bark_texture != nullptr) m += "map_Kd " + bark_png_name + "\n";
    }
    if (e.has_leaves()) {
        m += "\nnewmtl leaf\n";
        put_rgb(m, "Ka", {0.0f, 0.0f, 0.0f});
        put_rgb(m, "Kd", e.leaf_color);
        put_rgb(m, "Ks", {0.0f, 0.0f, 0.0f});
        m += "d 1\nillum 1\n";
        if (e.leaf_texture != nullptr) m += "map_Kd " + png_name + "\nmap_d " + png_name + "\n";
    }
    if (!e.lobes.empty()) {
        m += "\nnewmtl lobe\n";
        put_rgb(m, "Kd", {0.45f, 0.75f, 0.35f});
        m += "d 0.25\nillum 1\n";
    }
    if (!e.strokes.empty()) {
        m += "\nnewmtl stroke\n";
        put_rgb(m, "Kd", {1.0f, 0.55f, 0.1f});
        put_rgb(m, "Ke", {1.0f, 0.55f, 0.1f});
        m += "illum 0\n";
    }
    return m;
}

std::string build_obj(const PreparedExport& e, const std::string& mtl_name)
{
    std::string o = "# Lobesketch: " + e.name + " (metres, +Y up, origin at the trunk base)\n";
    o += "mtllib " + mtl_name + "\n";
    // OBJ indices are global and 1-based; v, vt and vn of a tree part advance together.
    std::size_t v_base = 0, vt_base = 0;
    for (const ExportPart& part : e.parts) {
        const SurfaceGeometry& g = part.geometry;
        o += "\no " + part.name + "\n";
        put_vec3_lines(o, "v ", g.positions);
        for (const glm::vec2& uv : g.uvs) {
            o += "vt ";
            put(o, uv.x);
            o += ' ';
            put(o, 1.0f - uv.y); // glTF/image rows run top-down, OBJ's v bottom-up
            o += '\n';
        }
        put_vec3_lines(o, "vn ", g.normals);
        o += part.kind == ExportPart::Kind::Leaves ? "usemtl leaf\n" : "usemtl bark\n";
        for (const auto& t : g.triangles) {
            o += 'f';
            for (std::uint32_t i : t) {
                o += ' ';
                put(o, v_base + i + 1);
                o += '/';
                put(o, vt_base + i + 1);
                o += '/';
                put(o, vt_base + i + 1);
            }
            o += '\n';
        }
        v_base += g.vertex_count();
        vt_base += g.vertex_count();
    }
    for (const ExportLobe& lobe : e.lobes) {
        o += "\no " + lobe.name + "\n";
        put_vec3_lines(o, "v ", lobe.positions);
        o += "usemtl lobe\n";
        for (const auto& t : lobe.triangles) {
            o += 'f';
            for (std::uint32_t i : t) {
                o += ' ';
                put(o, v_base + i + 1);
            }
            o += '\n';
        }
        v_base += lobe.positions.size();
    }
    for (const ExportPolyline& line : e.strokes) {
        o += "\no " + line.name + "\n";
        put_vec3_lines(o, "v ", line.points);
        o += "usemtl stroke\nl";
        for (std::size_t i = 0; i < line.points.size(); ++i) {
            o += ' ';
            put(o, v_base + i + 1);
        }
        o += '\n';
        v_base += line.points.size();
    }
    return o;
}

std::string_view bytes_view(const std::vector<std::uint8_t>& b)
{
    return {reinterpret_cast<const char*>(b.data()), b.size()};
}

} // namespace

ObjFiles encode_obj(const ExportScene& scene, const ExportOptions& options, const std::string& mtl_name,
                    const std::string& png_name, const std::string& bark_png_name)
{
    const PreparedExport e = prepare_export(scene, options);
    ObjFiles files;
    files.obj = build_obj(e, mtl_name);
    files.mtl = build_mtl(e, png_name, bark_png_name);
    if (e.has_leaves() && e.leaf_texture != nullptr) files.leaf_png = encode_png(*e.leaf_texture);
    if (e.has_branches() && e.bark_texture != nullptr) files.bark_png = encode_png(*e.bark_texture);
    return files;
}

void write_obj(const std::string& path, const ExportScene& scene, const ExportOptions& options)
{
    const std::filesystem::path obj_path(path);
    const std::filesystem::path mtl_path = std::filesystem::path(obj_path).replace_extension(".mtl");
    const std::filesystem::path png_path = obj_path.parent_path() / (obj_path.stem().string() + "_leaf.png");
    const std::filesystem::path bark_path = obj_path.parent_path() / (obj_path.stem().string() + "_bark.png");
    const ObjFiles files = encode_obj(scene, options, mtl_path.filename().string(), png_path.filename().string(),
                                      bark_path.filename().string());
    if (!files.leaf_png.empty()) write_file_atomic(png_path.string(), bytes_view(files.leaf_png));
    if (!files.bark_png.empty()) write_file_atomic(bark_path.string(), bytes_view(files.bark_png));
    write_file_atomic(mtl_path.string(), files.mtl);
    write_file_atomic(path, files.obj);
}

} // namespace lobe
