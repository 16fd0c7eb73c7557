/*
 * meshtrim.h: meshtrim's C API (libmeshtrim).
 *
 * Boundary detection, smoothed edges, trimming and border cleanup of
 * meshes made from 3D scans, on arrays, for C, C++ and any language with a
 * C foreign-function interface (C#, MATLAB's loadlibrary, LabVIEW, Julia,
 * ...). Each function runs what the `meshtrim` command of the same name
 * runs between reading its files and writing them, so the arrays it gives
 * are the command's, bit for bit; the report is the command's `--json`
 * report (without file names and read or write times).
 *
 * Arrays:
 *   - points and vertices: `count` rows of x, y, z doubles, row after row;
 *   - faces: `count` rows of three vertex indices (uint32_t, from 0),
 *     wound as the surface's outside sees them counter-clockwise.
 *   An array may be NULL only when its count is 0. Inputs are only read.
 *
 * Errors: every function that can fail returns MESHTRIM_OK (0), or
 * MESHTRIM_ERROR (1) for an input or option it cannot work on, or
 * MESHTRIM_INTERNAL_ERROR (2) for a fault of meshtrim's own (never a
 * crash: nothing unwinds into the caller). When `error` is not NULL, it
 * is set to NULL on success and otherwise to a message in UTF-8, which
 * the caller frees with meshtrim_string_free. The messages are the CLI's,
 * in parameter words ("points", "k", "max_deviation").
 *
 * Memory: what meshtrim allocates (MeshtrimMesh's arrays, reports,
 * messages) the caller frees with meshtrim_mesh_free or
 * meshtrim_string_free, never with free().
 *
 * Threads: the functions may be called from several threads at once; each
 * call also uses meshtrim's own worker threads (all cores). The results do
 * not depend on the number of threads.
 */
#ifndef MESHTRIM_H
#define MESHTRIM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MESHTRIM_OK 0
#define MESHTRIM_ERROR 1
#define MESHTRIM_INTERNAL_ERROR 2

/* MeshtrimOptions.view: the direction the scanner looked from, if known. */
#define MESHTRIM_VIEW_NONE 0
/* The scanner looked along the direction `view` (a vector). */
#define MESHTRIM_VIEW_ALONG 1
/* The scanner stood at the point `view`. */
#define MESHTRIM_VIEW_FROM 2

/* The options of every command, as the CLI's flags give them. Start from
 * meshtrim_default_options() and change what you need. */
typedef struct MeshtrimOptions {
    /* Neighbours per point for detection (--k); at least 4, default 30. */
    uint32_t k;
    /* Non-zero: detection measures the sampling's anisotropy (default);
     * zero: --no-anisotropy. */
    int anisotropy;
    /* Non-zero: edges move out to the estimated physical edge (default);
     * zero: --no-offset. */
    int offset;
    /* MESHTRIM_VIEW_NONE (default), _ALONG or _FROM, with `view`. */
    int view_kind;
    double view[3];
    /* clean only: make the mesh manifold and oriented first (--repair). */
    int repair;
    /* clean only: the border moves at most this far (--max-deviation, in
     * the mesh's units); 0 for no bound (default). */
    double max_deviation;
    /* clean only: first close the holes no wider than this (--fill-holes,
     * in the mesh's units); 0 to close none (default). */
    double fill_holes;
} MeshtrimOptions;

/* A mesh meshtrim made: free it with meshtrim_mesh_free. */
typedef struct MeshtrimMesh {
    double *vertices;     /* vertex_count rows of x, y, z */
    size_t vertex_count;
    uint32_t *faces;      /* face_count rows of three vertex indices */
    size_t face_count;
    char *report_json;    /* the command's report as JSON (UTF-8) */
} MeshtrimMesh;

/* meshtrim's version, e.g. "0.1.0" (static: do not free). */
const char *meshtrim_version(void);

/* The CLI's defaults: k = 30, anisotropy and offset on, no view, no
 * repair, no bound on the deviation, no hole closed. */
MeshtrimOptions meshtrim_default_options(void);

/* `meshtrim detect`: labels each of the point_count points boundary (1)
 * or interior (0) into `boundary` (point_count bytes), and its local
 * resolution into `beta` (point_count doubles; may be NULL). `report_json`
 * (may be NULL) receives the report. `options`: NULL for the defaults. */
int meshtrim_detect(const double *points, size_t point_count,
                    const MeshtrimOptions *options,
                    uint8_t *boundary, double *beta,
                    char **report_json, char **error);

/* `meshtrim edges CLOUD -o path`: detects the boundary, reconstructs the
 * smoothed edges and writes them to `path` (UTF-8), in the format its
 * extension names: .json, .obj, .svg, .dxf, .step/.stp or .igs/.iges;
 * written to a temporary file and renamed into place. `units` ("mm", "m"
 * or "in"; NULL for mm) is the length unit a STEP, IGES or DXF-with-splines
 * file declares; non-zero `dxf_splines` also writes each edge as a spline
 * into a .dxf file. `report_json` (may be NULL) receives the report. */
int meshtrim_edges(const double *points, size_t point_count,
                   const MeshtrimOptions *options,
                   const char *path, const char *units, int dxf_splines,
                   char **report_json, char **error);

/* `meshtrim MESH CLOUD OUT`: trims the mesh (screened Poisson's, say) to
 * the smoothed border of the cloud it was reconstructed from. On success
 * *out holds the trimmed mesh; on failure it is empty (all NULL and 0). */
int meshtrim_trim(const double *vertices, size_t vertex_count,
                  const uint32_t *faces, size_t face_count,
                  const double *points, size_t point_count,
                  const MeshtrimOptions *options,
                  MeshtrimMesh *out, char **error);

/* `meshtrim mesh CLOUD OUT`: the cloud's Delaunay mesh, cut along its
 * smoothed border. */
int meshtrim_mesh(const double *points, size_t point_count,
                  const MeshtrimOptions *options,
                  MeshtrimMesh *out, char **error);

/* `meshtrim clean IN OUT`: the triangulated scan with its jagged border
 * replaced by the smoothed one (options' repair and max_deviation
 * apply). */
int meshtrim_clean(const double *vertices, size_t vertex_count,
                   const uint32_t *faces, size_t face_count,
                   const MeshtrimOptions *options,
                   MeshtrimMesh *out, char **error);

/* `meshtrim clean IN OUT --edges path`'s curves: the mesh's border (a
 * cleaned mesh's, say), each loop split at its corners into edges through
 * its own vertices, nothing smoothed or moved, written to `path` as
 * meshtrim_edges writes (same formats, `units` and `dxf_splines`). Of
 * `options`, k and anisotropy apply (the corners' local resolution). */
int meshtrim_border_edges(const double *vertices, size_t vertex_count,
                          const uint32_t *faces, size_t face_count,
                          const MeshtrimOptions *options,
                          const char *path, const char *units, int dxf_splines,
                          char **error);

/* Frees a mesh's arrays and report and empties it; NULL is allowed. */
void meshtrim_mesh_free(MeshtrimMesh *mesh);

/* Frees a report or message; NULL is allowed. */
void meshtrim_string_free(char *text);

#ifdef __cplusplus
}
#endif

#endif /* MESHTRIM_H */
