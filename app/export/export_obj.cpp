#include "app/export/export_obj.h"

#include <algorithm>
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

/// "X_bark.png" → "X_bark_normal.png".
std::string normal_png_name(const std::string& bark_png_name)
{
    const std::size_t dot = bark_png_name.rfind('.');
    return dot == std::string::npos ? bark_png_name + "_normal" : bark_png_name.substr(0, dot) + "_normal" + bark_png_name.substr(dot);
}

std::string build_mtl(const PreparedExport& e, const std::string& png_name, const std::string& bark_png_name,
                      const std::string& billboard_png_name)
{
    std::string m = "# Lobesketch: materials of " + e.name + "\n";
    if (e.has_branches()) {
        m += "\nnewmtl bark\n";
        put_rgb(m, "Ka", {0.0f, 0.0f, 0.0f});
        // With a texture the colour is baked into it (tinted_texture): Kd 1 keeps it as is.
        put_rgb(m, "Kd", e.bark_texture != nullptr ? std::array<float, 3>{1.0f, 1.0f, 1.0f} : e.bark_color);
        put_rgb(m, "Ks", {0.0f, 0.0f, 0.0f});
        m += "d 1\nillum 1\n";
        if (e.bark_texture != nullptr) m += "map_Kd " + bark_png_name + "\n";
        if (!e.bark_normal_map.pixels.empty()) m += "map_Bump " + normal_png_name(bark_png_name) + "\n";
    }
    if (e.has_leaves()) {
        m += "\nnewmtl leaf\n";
        put_rgb(m, "Ka", {0.0f, 0.0f, 0.0f});
        put_rgb(m, "Kd", e.leaf_texture != nullptr ? std::array<float, 3>{1.0f, 1.0f, 1.0f} : e.leaf_color);
        put_rgb(m, "Ks", {0.0f, 0.0f, 0.0f});
        m += "d 1\nillum 1\n";
        if (e.leaf_texture != nullptr) m += "map_Kd " + png_name + "\nmap_d " + png_name + "\n";
    }
    if (e.has_billboard()) {
        m += "\nnewmtl billboard\n";
        put_rgb(m, "Ka", {0.0f, 0.0f, 0.0f});
        put_rgb(m, "Kd", {1.0f, 1.0f, 1.0f});
        put_rgb(m, "Ks", {0.0f, 0.0f, 0.0f});
        m += "d 1\nillum 1\nmap_Kd " + billboard_png_name + "\nmap_d " + billboard_png_name + "\n";
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

/// The OBJ of level `lod` of `e`; with `extras`, the lobes and strokes after it.
std::string build_obj(const PreparedExport& e, const std::string& mtl_name, int lod, bool extras)
{
    std::string o = "# Lobesketch: " + e.name + " LOD" + std::to_string(lod) + " (metres, +Y up, origin at the trunk base)\n";
    o += "mtllib " + mtl_name + "\n";
    // OBJ indices are global and 1-based; v, vt and vn of a tree part advance together.
    std::size_t v_base = 0, vt_base = 0;
    for (const ExportPart& part : e.parts) {
        if (part.lod != lod) continue;
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
        o += part.kind == ExportPart::Kind::Leaves      ? "usemtl leaf\n"
             : part.kind == ExportPart::Kind::Billboard ? "usemtl billboard\n"
                                                        : "usemtl bark\n";
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
    if (!extras) return o;
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
                    const std::string& png_name, const std::string& bark_png_name, const std::string& billboard_png_name)
{
    const PreparedExport e = prepare_export(scene, options);
    ObjFiles files;
    // The levels written, ascending: the first goes into the main OBJ with the extras.
    std::vector<int> lods;
    for (const ExportPart& part : e.parts)
        if (lods.empty() || lods.back() != part.lod) lods.push_back(part.lod);
    if (lods.empty()) lods.push_back(options.lods.empty() ? 0 : *std::min_element(options.lods.begin(), options.lods.end()));
    files.obj = build_obj(e, mtl_name, lods[0], true);
    for (std::size_t i = 1; i < lods.size(); ++i) files.lod_objs.emplace_back(lods[i], build_obj(e, mtl_name, lods[i], false));
    files.mtl = build_mtl(e, png_name, bark_png_name, billboard_png_name);
    if (e.has_billboard()) files.billboard_png = encode_png(e.billboard_texture);
    if (e.has_branches() && !e.bark_normal_map.pixels.empty()) files.bark_normal_png = encode_png(e.bark_normal_map);
    if (e.has_leaves() && e.leaf_texture != nullptr) files.leaf_png = encode_png(tinted_texture(*e.leaf_texture, e.leaf_color));
    if (e.has_branches() && e.bark_texture != nullptr) files.bark_png = encode_png(tinted_texture(*e.bark_texture, e.bark_color));
    return files;
}

std::vector<std::string> write_obj(const std::string& path, const ExportScene& scene, const ExportOptions& options)
{
    const std::filesystem::path obj_path(path);
    const std::string stem = obj_path.stem().string();
    const std::filesystem::path mtl_path = std::filesystem::path(obj_path).replace_extension(".mtl");
    const std::filesystem::path png_path = obj_path.parent_path() / (stem + "_leaf.png");
    const std::filesystem::path bark_path = obj_path.parent_path() / (stem + "_bark.png");
    const std::filesystem::path billboard_path = obj_path.parent_path() / (stem + "_billboard.png");
    const ObjFiles files = encode_obj(scene, options, mtl_path.filename().string(), png_path.filename().string(),
                                      bark_path.filename().string(), billboard_path.filename().string());
    std::vector<std::string> written{path, mtl_path.string()};
    if (!files.leaf_png.empty()) {
        write_file_atomic(png_path.string(), bytes_view(files.leaf_png));
        written.push_back(png_path.string());
    }
    if (!files.bark_png.empty()) {
        write_file_atomic(bark_path.string(), bytes_view(files.bark_png));
        written.push_back(bark_path.string());
    }
    if (!files.bark_normal_png.empty()) {
        const std::filesystem::path p = obj_path.parent_path() / normal_png_name(bark_path.filename().string());
        write_file_atomic(p.string(), bytes_view(files.bark_normal_png));
        written.push_back(p.string());
    }
    if (!files.billboard_png.empty()) {
        write_file_atomic(billboard_path.string(), bytes_view(files.billboard_png));
        written.push_back(billboard_path.string());
    }
    write_file_atomic(mtl_path.string(), files.mtl);
    for (const auto& [lod, text] : files.lod_objs) {
        const std::filesystem::path p = obj_path.parent_path() / (stem + "_LOD" + std::to_string(lod) + obj_path.extension().string());
        write_file_atomic(p.string(), text);
        written.push_back(p.string());
    }
    write_file_atomic(path, files.obj);
    return written;
}

} // namespace lobe
