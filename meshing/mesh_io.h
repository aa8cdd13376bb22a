#pragma once
/// \file mesh_io.h
/// Reading and writing triangle meshes (OBJ, PLY, OFF) without CGAL or OpenMesh. Mesh files
/// come from users and are untrusted: every malformed file gives one FileError whose
/// one-line message starts with the file name, never a crash, a hang or unbounded memory.
/// See docs/lobes-from-models.md.

#include <cstddef>
#include <string>

#include "core/mesh.h"

namespace lobe {

/// What a mesh file may hold; anything beyond is refused before memory is allocated for it.
struct MeshIoLimits {
    static constexpr std::size_t max_file_bytes = std::size_t{1} << 30; ///< 1 GiB
    static constexpr std::size_t max_vertices = 10'000'000;
    static constexpr std::size_t max_triangles = 20'000'000; ///< after fan triangulation
};

/// Reads a mesh; the format is chosen by the extension (.obj, .ply, .off, any case) or, for
/// other names, by the file's first bytes.
/// - OBJ: `v` and `f` lines; polygons are fan-triangulated; indices may be negative
///   (relative) and come as `i`, `i/t`, `i//n` or `i/t/n`; `l` lines become
///   TriangleMesh::feature_edges (one per segment); other statements and `#` comments are
///   ignored. A face may refer only to vertices defined above it.
/// - PLY: ASCII and binary (little and big endian); the vertex element's x, y, z (any scalar
///   type) and the face element's `vertex_indices` (or `vertex_index`) list (any integer
///   count and index types); an `edge` element with `vertex1`, `vertex2` becomes
///   feature_edges; every other element and property is skipped. The vertex element must
///   come before the face element (as every writer does).
/// - OFF (also COFF, NOFF, …): counts line, vertices (extra values per line ignored),
///   faces `n i1 … in` (fan-triangulated, trailing colour ignored). Binary OFF is refused.
///
/// Faces are kept as written (degenerate or duplicate triangles included): repair_mesh()
/// cleans them. Coordinates are converted to float.
/// \throw FileError (one line: "<path>: [line N: ]<problem>") when the file is missing,
/// larger than MeshIoLimits, truncated or malformed, declares more vertices or faces than
/// MeshIoLimits or than its size can hold, has a non-finite coordinate, a face with fewer
/// than 3 vertices or an index out of range, or has no vertex or no face.
TriangleMesh read_mesh(const std::string& path);

/// Parses a mesh held in memory, exactly as read_mesh parses a file's bytes: the format comes
/// from `name`'s extension or, failing that, from the first bytes; `name` starts the messages.
/// \throw FileError as read_mesh.
TriangleMesh parse_mesh(const std::string& bytes, const std::string& name);

/// Writes binary little-endian PLY (float x, y, z; uchar-int vertex_indices; an `edge`
/// element with int vertex1, vertex2 when the mesh has feature edges), atomically
/// (write_file_atomic).
/// \throw InvalidInput when an index is out of range; FileError when writing fails.
void write_ply(const std::string& path, const TriangleMesh& mesh);

/// Writes OBJ (`v`, 1-based `f`, and `l` lines for feature edges) atomically; coordinates
/// with 9 significant digits, so float positions read back exactly.
/// \throw InvalidInput when an index is out of range; FileError when writing fails.
void write_obj(const std::string& path, const TriangleMesh& mesh);

} // namespace lobe
