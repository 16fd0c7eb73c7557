/*
 * arrays.c: meshtrim's C API on raw arrays, as a program.
 *
 *   arrays clean  VERTICES FACES OUT [MAX_DEVIATION]
 *   arrays trim   VERTICES FACES POINTS OUT
 *   arrays mesh   POINTS OUT
 *   arrays detect POINTS OUT
 *   arrays edges  POINTS EDGES_FILE [UNITS]
 *   arrays border VERTICES FACES EDGES_FILE [UNITS]
 *
 * VERTICES and POINTS are files of little-endian doubles (x, y, z per
 * row), FACES of little-endian uint32 (three per face), as numpy's
 * `tofile` writes them. A mesh result is written to OUT.vertices,
 * OUT.faces and OUT.json (the report); detect writes OUT.boundary (one
 * byte per point), OUT.beta and OUT.json. On an error the message goes to
 * stderr and the exit status is 1 (2 for meshtrim's own fault).
 *
 * Build: cc -std=c99 -Icrates/capi/include crates/capi/examples/arrays.c \
 *            -Ltarget/release -lmeshtrim -Wl,-rpath,$PWD/target/release
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "meshtrim.h"

/* The whole file at `path`, its size in *bytes; NULL (with a message) if
 * it cannot be read. */
static void *read_file(const char *path, size_t *bytes) {
    FILE *f = fopen(path, "rb");
    if (!f) {
        perror(path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    void *data = malloc(size > 0 ? (size_t)size : 1);
    if (!data || fread(data, 1, (size_t)size, f) != (size_t)size) {
        fprintf(stderr, "%s: cannot read\n", path);
        free(data);
        fclose(f);
        return NULL;
    }
    fclose(f);
    *bytes = (size_t)size;
    return data;
}

static int write_file(const char *prefix, const char *suffix, const void *data, size_t bytes) {
    char path[4096];
    snprintf(path, sizeof path, "%s%s", prefix, suffix);
    FILE *f = fopen(path, "wb");
    if (!f || (bytes > 0 && fwrite(data, 1, bytes, f) != bytes)) {
        perror(path);
        if (f) fclose(f);
        return 1;
    }
    return fclose(f) != 0;
}

/* Rows of three values of `size` bytes each, read from `path`. */
static void *read_rows(const char *path, size_t size, size_t *rows) {
    size_t bytes = 0;
    void *data = read_file(path, &bytes);
    if (data && bytes % (3 * size) != 0) {
        fprintf(stderr, "%s: %zu bytes are not whole rows of three\n", path, bytes);
        free(data);
        return NULL;
    }
    *rows = bytes / (3 * size);
    return data;
}

/* Reports a failed call and gives the exit status. */
static int failed(int status, char *error) {
    fprintf(stderr, "error: %s\n", error ? error : "(no message)");
    meshtrim_string_free(error);
    return status;
}

static int write_mesh(const char *out, MeshtrimMesh *mesh) {
    int bad = write_file(out, ".vertices", mesh->vertices, mesh->vertex_count * 3 * sizeof(double))
           || write_file(out, ".faces", mesh->faces, mesh->face_count * 3 * sizeof(uint32_t))
           || write_file(out, ".json", mesh->report_json, strlen(mesh->report_json));
    printf("%zu vertices, %zu faces\n", mesh->vertex_count, mesh->face_count);
    meshtrim_mesh_free(mesh);
    return bad;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: arrays clean|border|trim|mesh|detect|edges FILES... (see the source)\n");
        return 64;
    }
    const char *command = argv[1];
    MeshtrimOptions options = meshtrim_default_options();
    MeshtrimMesh mesh;
    char *error = NULL;
    int status = MESHTRIM_OK;
    size_t n = 0, m = 0, p = 0;

    if (strcmp(command, "clean") == 0 && argc >= 5) {
        double *vertices = read_rows(argv[2], sizeof(double), &n);
        uint32_t *faces = read_rows(argv[3], sizeof(uint32_t), &m);
        if (!vertices || !faces) return 66;
        if (argc > 5) options.max_deviation = atof(argv[5]);
        status = meshtrim_clean(vertices, n, faces, m, &options, &mesh, &error);
        free(vertices);
        free(faces);
        return status == MESHTRIM_OK ? write_mesh(argv[4], &mesh) : failed(status, error);
    }
    if (strcmp(command, "border") == 0 && argc >= 5) {
        double *vertices = read_rows(argv[2], sizeof(double), &n);
        uint32_t *faces = read_rows(argv[3], sizeof(uint32_t), &m);
        if (!vertices || !faces) return 66;
        const char *units = argc > 5 ? argv[5] : NULL;
        status = meshtrim_border_edges(vertices, n, faces, m, &options, argv[4], units, 0, &error);
        free(vertices);
        free(faces);
        return status == MESHTRIM_OK ? 0 : failed(status, error);
    }
    if (strcmp(command, "trim") == 0 && argc >= 6) {
        double *vertices = read_rows(argv[2], sizeof(double), &n);
        uint32_t *faces = read_rows(argv[3], sizeof(uint32_t), &m);
        double *points = read_rows(argv[4], sizeof(double), &p);
        if (!vertices || !faces || !points) return 66;
        status = meshtrim_trim(vertices, n, faces, m, points, p, &options, &mesh, &error);
        free(vertices);
        free(faces);
        free(points);
        return status == MESHTRIM_OK ? write_mesh(argv[5], &mesh) : failed(status, error);
    }
    double *points = read_rows(argv[2], sizeof(double), &p);
    if (!points) return 66;
    if (strcmp(command, "mesh") == 0) {
        status = meshtrim_mesh(points, p, &options, &mesh, &error);
        free(points);
        return status == MESHTRIM_OK ? write_mesh(argv[3], &mesh) : failed(status, error);
    }
    if (strcmp(command, "detect") == 0) {
        uint8_t *boundary = malloc(p ? p : 1);
        double *beta = malloc(p ? p * sizeof(double) : 1);
        char *report = NULL;
        status = meshtrim_detect(points, p, &options, boundary, beta, &report, &error);
        free(points);
        if (status != MESHTRIM_OK) return failed(status, error);
        int bad = write_file(argv[3], ".boundary", boundary, p)
               || write_file(argv[3], ".beta", beta, p * sizeof(double))
               || write_file(argv[3], ".json", report, strlen(report));
        meshtrim_string_free(report);
        free(boundary);
        free(beta);
        return bad;
    }
    if (strcmp(command, "edges") == 0) {
        const char *units = argc > 4 ? argv[4] : NULL;
        status = meshtrim_edges(points, p, &options, argv[3], units, 0, NULL, &error);
        free(points);
        return status == MESHTRIM_OK ? 0 : failed(status, error);
    }
    free(points);
    fprintf(stderr, "unknown command %s\n", command);
    return 64;
}
