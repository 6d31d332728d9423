// A C interface to TetGen 1.5 (Debian libtet1.5-dev) for blmesh's core fill.
//
// Only plain data crosses the boundary: the Rust side passes a closed triangle surface (points,
// triangles, markers, optional per-point sizes, hole points) and a switch string, and gets back
// an opaque result it copies out and frees. Every C++ exception (TetGen's library build reports
// errors with `throw int`, allocation failures throw std::bad_alloc) is caught here and turned
// into an error code, so none unwinds into Rust.

#define TETLIBRARY
#include <tetgen.h>

#include <cstring>
#include <exception>
#include <new>

namespace {

// Error codes beyond TetGen's own (1 out of memory, 2 internal error, 3 self-intersection,
// 4 small input feature, 5 close facets, 10 input error).
const int TG_OK = 0;
const int TG_BAD_ARGUMENT = 100;
const int TG_STD_EXCEPTION = 101;
const int TG_UNKNOWN_EXCEPTION = 102;

void copy_message(char *message, size_t capacity, const char *text) {
  if (message == nullptr || capacity == 0) {
    return;
  }
  std::strncpy(message, text, capacity - 1);
  message[capacity - 1] = '\0';
}

// Fill `in` with the surface: one facet of one triangle per input triangle.
void load_input(tetgenio &in, int n_points, const double *points, const double *sizes, int n_triangles,
                const int *triangles, const int *markers, int n_holes, const double *holes) {
  in.firstnumber = 0;
  in.numberofpoints = n_points;
  in.pointlist = new REAL[3 * (size_t)n_points];
  std::memcpy(in.pointlist, points, sizeof(double) * 3 * (size_t)n_points);
  if (sizes != nullptr) {
    in.numberofpointmtrs = 1;
    in.pointmtrlist = new REAL[(size_t)n_points];
    std::memcpy(in.pointmtrlist, sizes, sizeof(double) * (size_t)n_points);
  }
  in.facetmarkerlist = new int[(size_t)n_triangles];
  in.facetlist = new tetgenio::facet[(size_t)n_triangles];
  // Empty facets first, so that the destructor frees only what was allocated if `new` throws.
  for (int t = 0; t < n_triangles; t++) {
    tetgenio::facet &f = in.facetlist[t];
    f.polygonlist = nullptr;
    f.numberofpolygons = 0;
    f.holelist = nullptr;
    f.numberofholes = 0;
  }
  in.numberoffacets = n_triangles;
  for (int t = 0; t < n_triangles; t++) {
    tetgenio::facet &f = in.facetlist[t];
    f.polygonlist = new tetgenio::polygon[1];
    f.polygonlist[0].vertexlist = new int[3];
    f.polygonlist[0].numberofvertices = 3;
    f.numberofpolygons = 1;
    for (int k = 0; k < 3; k++) {
      f.polygonlist[0].vertexlist[k] = triangles[3 * (size_t)t + k];
    }
    in.facetmarkerlist[t] = markers[t];
  }
  if (n_holes > 0) {
    in.numberofholes = n_holes;
    in.holelist = new REAL[3 * (size_t)n_holes];
    std::memcpy(in.holelist, holes, sizeof(double) * 3 * (size_t)n_holes);
  }
}

}  // namespace

extern "C" {

// The tetrahedralization, owned by the shim until blmesh_tetgen_free.
struct BlmeshTetgenResult {
  tetgenio out;
};

}  // extern "C"

namespace {

// Run TetGen on the input that `load` puts in a tetgenio. On success (return 0) `*result` holds
// the output; on failure it is null and `message` says what happened.
template <typename Load>
int run_tetgen(Load load, const char *switches, BlmeshTetgenResult **result, char *message,
               size_t message_capacity) {
  BlmeshTetgenResult *owned = nullptr;
  try {
    tetgenio in;
    load(in);
    owned = new BlmeshTetgenResult();
    char switch_buffer[1024];
    std::strncpy(switch_buffer, switches, sizeof switch_buffer - 1);
    switch_buffer[sizeof switch_buffer - 1] = '\0';
    tetrahedralize(switch_buffer, &in, &owned->out);
    *result = owned;
    return TG_OK;
  } catch (int code) {
    delete owned;
    copy_message(message, message_capacity, "TetGen stopped with an error code");
    return code == TG_OK ? 2 : code;
  } catch (const std::exception &e) {
    delete owned;
    copy_message(message, message_capacity, e.what());
    return TG_STD_EXCEPTION;
  } catch (...) {
    delete owned;
    copy_message(message, message_capacity, "unknown C++ exception");
    return TG_UNKNOWN_EXCEPTION;
  }
}

}  // namespace

extern "C" {

// Run TetGen. On success (return 0) `*result` holds the output; on failure it is null and
// `message` (capacity `message_capacity`, may be null) says what happened.
int blmesh_tetgen_run(int n_points, const double *points, const double *sizes, int n_triangles,
                      const int *triangles, const int *markers, int n_holes, const double *holes,
                      const char *switches, BlmeshTetgenResult **result, char *message,
                      size_t message_capacity) {
  if (result == nullptr) {
    copy_message(message, message_capacity, "no place for the result");
    return TG_BAD_ARGUMENT;
  }
  *result = nullptr;
  if (n_points < 4 || n_triangles < 4 || n_holes < 0 || points == nullptr || triangles == nullptr ||
      markers == nullptr || switches == nullptr || (n_holes > 0 && holes == nullptr) ||
      std::strlen(switches) >= 1000) {
    copy_message(message, message_capacity, "bad arguments");
    return TG_BAD_ARGUMENT;
  }
  auto load = [&](tetgenio &in) {
    load_input(in, n_points, points, sizes, n_triangles, triangles, markers, n_holes, holes);
  };
  return run_tetgen(load, switches, result, message, message_capacity);
}

// The Delaunay tetrahedralization of a bare point set (switches without `p`), as
// blmesh_tetgen_run.
int blmesh_tetgen_points(int n_points, const double *points, const char *switches,
                         BlmeshTetgenResult **result, char *message, size_t message_capacity) {
  if (result == nullptr) {
    copy_message(message, message_capacity, "no place for the result");
    return TG_BAD_ARGUMENT;
  }
  *result = nullptr;
  if (n_points < 4 || points == nullptr || switches == nullptr || std::strlen(switches) >= 1000) {
    copy_message(message, message_capacity, "bad arguments");
    return TG_BAD_ARGUMENT;
  }
  auto load = [&](tetgenio &in) {
    in.firstnumber = 0;
    in.numberofpoints = n_points;
    in.pointlist = new REAL[3 * (size_t)n_points];
    std::memcpy(in.pointlist, points, sizeof(double) * 3 * (size_t)n_points);
  };
  return run_tetgen(load, switches, result, message, message_capacity);
}

// Sizes of the output: points, tetrahedra, boundary triangles.
void blmesh_tetgen_counts(const BlmeshTetgenResult *result, int *n_points, int *n_tets,
                          int *n_boundary_triangles) {
  *n_points = result->out.numberofpoints;
  *n_tets = result->out.numberofcorners == 4 ? result->out.numberoftetrahedra : 0;
  *n_boundary_triangles = result->out.trifacelist != nullptr ? result->out.numberoftrifaces : 0;
}

// Copy the output into buffers sized by blmesh_tetgen_counts (3 doubles per point, 4 ints per
// tetrahedron, 3 ints per boundary triangle; the last may be null).
void blmesh_tetgen_copy(const BlmeshTetgenResult *result, double *points, int *tets,
                        int *boundary_triangles) {
  const tetgenio &out = result->out;
  if (out.numberofpoints > 0) {
    std::memcpy(points, out.pointlist, sizeof(double) * 3 * (size_t)out.numberofpoints);
  }
  if (out.numberofcorners == 4 && out.numberoftetrahedra > 0) {
    std::memcpy(tets, out.tetrahedronlist, sizeof(int) * 4 * (size_t)out.numberoftetrahedra);
  }
  if (boundary_triangles != nullptr && out.trifacelist != nullptr && out.numberoftrifaces > 0) {
    std::memcpy(boundary_triangles, out.trifacelist, sizeof(int) * 3 * (size_t)out.numberoftrifaces);
  }
}

void blmesh_tetgen_free(BlmeshTetgenResult *result) { delete result; }

}  // extern "C"
