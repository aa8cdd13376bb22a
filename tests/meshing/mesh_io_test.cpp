#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/errors.h"
#include "meshing/mesh_io.h"
#include "tests/support/test_data.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

/// A tetrahedron with one feature edge, outward oriented.
TriangleMesh tetrahedron()
{
    TriangleMesh m;
    m.positions = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, {0.1234567f, -0.5f, 1.f}};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    m.feature_edges = {{0, 1}, {1, 3}};
    return m;
}

void write_bytes(const std::string& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <class T>
void append_raw(std::string& s, T v, bool big_endian)
{
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_endian)
        for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    s.append(reinterpret_cast<const char*>(b), sizeof(T));
}

void expect_same(const TriangleMesh& a, const TriangleMesh& b)
{
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]) << i;
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.feature_edges, b.feature_edges);
}

/// Expects a FileError whose one-line message starts with the path and mentions `needle`.
void expect_file_error(const std::string& path, const std::string& needle)
{
    try {
        read_mesh(path);
        ADD_FAILURE() << path << ": no error";
    } catch (const FileError& e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        EXPECT_NE(msg.find(needle), std::string::npos) << "expected '" << needle << "' in: " << msg;
    }
}

} // namespace

TEST(MeshIo, PlyRoundTripIsExact)
{
    const std::string path = test::temp_dir("mesh_io_ply") + "/tet.ply";
    write_ply(path, tetrahedron());
    expect_same(read_mesh(path), tetrahedron());
}

TEST(MeshIo, ObjRoundTripIsExact)
{
    const std::string path = test::temp_dir("mesh_io_obj") + "/tet.obj";
    write_obj(path, tetrahedron());
    expect_same(read_mesh(path), tetrahedron());
}

TEST(MeshIo, ObjFormsNegativeIndicesAndPolygons)
{
    const std::string path = test::temp_dir("mesh_io_forms") + "/forms.obj";
    write_bytes(path, "# a comment\r\n"
                      "mtllib x.mtl\n"
                      "v 0 0 0\nv 1 0 0 # trailing comment\nv 1 1 0\nv 0 1 0\n"
                      "vt 0 0\nvn 0 0 1\n"
                      "g quad\n"
                      "f 1/1/1 2/1/1 3/1/1 4/1/1\n" // a quad: two triangles
                      "v +0.5 0.5 1e0\n"
                      "f -1//1 -4//1 -5//1\n"        // negative (relative) references
                      "f 1/1 2/1 5/1\n"
                      "l 1 2 3\n");
    const TriangleMesh m = read_mesh(path);
    ASSERT_EQ(m.positions.size(), 5u);
    EXPECT_EQ(m.positions[4], glm::vec3(0.5f, 0.5f, 1.f));
    const std::vector<std::array<int, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {4, 1, 0}, {0, 1, 4}};
    EXPECT_EQ(m.triangles, expected);
    const std::vector<std::array<int, 2>> lines = {{0, 1}, {1, 2}};
    EXPECT_EQ(m.feature_edges, lines);
}

TEST(MeshIo, PlyAsciiAndBigEndianWithExtraProperties)
{
    const std::string dir = test::temp_dir("mesh_io_ply_forms");
    write_bytes(dir + "/a.ply", "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\n"
                                "property double x\nproperty double y\nproperty double z\nproperty uchar red\n"
                                "element face 1\nproperty list uchar int vertex_indices\nproperty float quality\n"
                                "element material 1\nproperty list int float values\n"
                                "end_header\n0 0 0 255\n1 0 0 0\n1 1 0 1\n0 1 0 2\n4 0 1 2 3 0.5\n2 1.5 2.5\n");
    TriangleMesh a = read_mesh(dir + "/a.ply");
    EXPECT_EQ(a.positions.size(), 4u);
    EXPECT_EQ(a.triangles.size(), 2u);

    // Binary big endian: float normals before x, a ushort count with uint indices, and an
    // element after the faces that is skipped.
    std::string b = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float nx\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 1\nproperty list ushort uint vertex_indices\n"
                    "element extra 2\nproperty short s\nend_header\n";
    const float v[3][3] = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}};
    for (const auto& p : v) {
        append_raw(b, 9.f, true);
        for (float c : p) append_raw(b, c, true);
    }
    append_raw(b, std::uint16_t{3}, true);
    for (std::uint32_t i : {0u, 1u, 2u}) append_raw(b, i, true);
    append_raw(b, std::int16_t{7}, true);
    append_raw(b, std::int16_t{8}, true);
    write_bytes(dir + "/b.ply", b);
    const TriangleMesh m = read_mesh(dir + "/b.ply");
    ASSERT_EQ(m.positions.size(), 3u);
    EXPECT_EQ(m.positions[2], glm::vec3(0.f, 3.f, 0.f));
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 1, 2}));
}

TEST(MeshIo, ReadsOff)
{
    const std::string path = test::temp_dir("mesh_io_off") + "/q.off";
    write_bytes(path, "OFF\n# comment\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n");
    const TriangleMesh m = read_mesh(path);
    EXPECT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.triangles.size(), 2u);
}

TEST(MeshIo, ReadsTheReferenceModels)
{
    struct Model {
        const char* file;
        std::size_t vertices;
    };
    for (const Model& model : {Model{"stanford-bunny.obj", 35947}, Model{"cow.obj", 2903},
                               Model{"nefertiti.obj", 49971}, Model{"spot.obj", 2930}}) {
        const std::string path = test::shared_data(std::string("data/models/") + model.file);
        if (path.empty()) return;
        const TriangleMesh m = read_mesh(path);
        EXPECT_EQ(m.positions.size(), model.vertices) << model.file;
        EXPECT_GT(m.triangles.size(), model.vertices) << model.file;
    }
}

TEST(MeshIo, MalformedFilesGiveOneLineFileErrors)
{
    const std::string dir = test::temp_dir("mesh_io_bad");
    struct Case {
        const char* name;
        std::string content;
        const char* needle;
    };
    const std::string ply_head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face 1\n"
                                 "property list uchar int vertex_indices\nend_header\n";
    std::string truncated = ply_head;
    for (int i = 0; i < 9; ++i) append_raw(truncated, 0.5f * static_cast<float>(i), false);
    append_raw(truncated, std::uint8_t{4}, false); // a quad with one index missing: the
    for (std::int32_t i : {0, 1, 2}) append_raw(truncated, i, false); // size check passes
    std::string huge = "ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\nproperty float x\n"
                       "property float y\nproperty float z\nelement face 1\n"
                       "property list uchar int vertex_indices\nend_header\n";
    huge += std::string(64, '\0');
    const std::vector<Case> cases = {
        {"empty.obj", "", "empty"},
        {"empty.ply", "", "empty"},
        {"nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"},
        {"comments.obj", "# nothing\n", "no vertices"},
        {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: vertex index 4 out of range"},
        {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4"},
        {"nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "line 2"},
        {"inf.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n", "non-finite"},
        {"word.obj", "v 0 zero 0\n", "line 1: bad coordinate 'zero'"},
        {"two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "line 3: face with 2 vertices"},
        {"counts.off", "OFF\n5 2 0\n0 0 0\n1 0 0\n0 1 0\n", "more than the file"},
        {"short.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n3 0 1 2\n", "truncated"},
        {"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "line 6: vertex index 3 out of range"},
        {"range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
         "out of range"},
        {"truncated.ply", truncated, "truncated binary data in element 'face' #0"},
        {"huge.ply", huge, "2147483648"},
        {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "end_header"},
        {"magic.ply", "plx\n", "not a PLY file"},
        {"badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "unknown property type"},
        {"nan.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
         "non-finite"},
    };
    for (const Case& c : cases) {
        const std::string path = dir + "/" + c.name;
        write_bytes(path, c.content);
        SCOPED_TRACE(c.name);
        expect_file_error(path, c.needle);
    }
    expect_file_error(dir + "/missing.obj", "no such file");
}

TEST(MeshIo, WritingABrokenMeshIsRefused)
{
    TriangleMesh m = tetrahedron();
    m.triangles.push_back({0, 1, 9});
    const std::string path = test::temp_dir("mesh_io_write_bad") + "/x.ply";
    EXPECT_THROW(write_ply(path, m), InvalidInput);
    EXPECT_THROW(write_obj(path, m), InvalidInput);
}

TEST(MeshIo, ParsesBytesInMemoryAsReadMeshReadsAFile)
{
    const std::string path = test::temp_dir("mesh_io_parse") + "/tet.ply";
    write_ply(path, tetrahedron());
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    expect_same(parse_mesh(bytes, "tet.ply"), tetrahedron());
    // Without a known extension the first bytes decide, as for read_mesh.
    expect_same(parse_mesh(bytes, "mesh.bin"), tetrahedron());
    EXPECT_EQ(parse_mesh("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "x").triangles.size(), 1u);
    try {
        parse_mesh("", "empty.obj");
        ADD_FAILURE() << "no error";
    } catch (const FileError& e) {
        EXPECT_STREQ(e.what(), "empty.obj: empty file");
    }
}
