/* The ONNX Runtime engine: a worker process (ort_worker.js) and the message protocol spoken
 * with it over a Unix socket. The protocol is written down at the top of ort_worker.js. */
#define _GNU_SOURCE /* memfd_create */
#include "classifier_ort.h"

#include <errno.h>
#include <jansson.h>
#include <omp.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include "vf/fsutil.h"
#include "vf/process.h"
#include "vf/resources.h"

extern const char vf__ort_worker_script[]; /* generated from ort_worker.js by CMake */

#define REQUEST_MAGIC 0x51524656u /* 'VFRQ' */
#define KIND_JSON 1u
#define KIND_LOGITS 2u
/* Longest wait for one answer: loading a large transformer or a batch of it on 2 cores. */
#define ANSWER_TIMEOUT_S 600
#define INSTALL_HINT "run scripts/setup.sh, or npm install --ignore-scripts onnxruntime-node"

struct vf_ort {
    int channel;   /* our end of the socket */
    int output_fd; /* memfd with the worker's stdout and stderr */
    int pid;
    int nhwc;       /* the model takes [N,S,S,3] */
    int input_size; /* 0: symbolic */
    char version[32];
    char path[VF_PATH_MAX];
    float *scratch; /* NHWC copy of a batch */
    size_t scratch_floats;
};

static vf_status find_package(char *out, size_t size)
{
    const char *env = getenv("VF_ONNXRUNTIME_DIR");
    char base[VF_PATH_MAX];
    if (env && *env)
        snprintf(base, sizeof base, "%s", env);
    else if (vf_user_data_path("onnxruntime", base, sizeof base) != VF_OK)
        return VF_EINTERNAL;
    if (vf_path_join(out, size, base, "node_modules/onnxruntime-node") != VF_OK)
        return VF_EINTERNAL;
    char manifest[VF_PATH_MAX];
    if (vf_path_join(manifest, sizeof manifest, out, "package.json") != VF_OK ||
        !vf_is_file(manifest))
        return vf_fail(VF_EINTERNAL, "ONNX Runtime is not installed (no %s; %s)", out,
                       INSTALL_HINT);
    return VF_OK;
}

/* node and the package folder (both VF_PATH_MAX buffers), or what is missing. */
static vf_status find_runtime(char *node, char *package)
{
    vf_status status =
        vf_find_program("VF_NODE", "node", "apt-get install nodejs npm", node, VF_PATH_MAX);
    return status == VF_OK ? find_package(package, VF_PATH_MAX) : status;
}

vf_status vf_ort_available(void)
{
    char node[VF_PATH_MAX], package[VF_PATH_MAX];
    return find_runtime(node, package);
}

/* The last non-empty line the worker printed (a crash's reason), or "". */
static void worker_output(const vf_ort *ort, char *out, size_t size)
{
    char text[2048];
    off_t end = lseek(ort->output_fd, 0, SEEK_END);
    off_t start = end > (off_t)sizeof text - 1 ? end - (off_t)sizeof text + 1 : 0;
    ssize_t n = pread(ort->output_fd, text, sizeof text - 1, start);
    text[n > 0 ? n : 0] = '\0';
    size_t len = strlen(text);
    while (len > 0 && (text[len - 1] == '\n' || text[len - 1] == ' '))
        text[--len] = '\0';
    const char *line = strrchr(text, '\n');
    snprintf(out, size, "%s", line ? line + 1 : text);
}

static vf_status worker_gone(vf_ort *ort, const char *doing)
{
    char why[512];
    int code = vf_process_finish(ort->pid, 1.0);
    ort->pid = -1;
    worker_output(ort, why, sizeof why);
    return vf_fail(VF_EINTERNAL, "the ONNX Runtime worker stopped while %s (exit %d)%s%s", doing,
                   code, why[0] ? ": " : "", why);
}

/* Read exactly size bytes, waiting at most ANSWER_TIMEOUT_S for each piece. */
static vf_status read_exact(vf_ort *ort, void *buf, size_t size, const char *doing)
{
    char *p = buf;
    while (size > 0) {
        struct pollfd pfd = {.fd = ort->channel, .events = POLLIN};
        int ready = poll(&pfd, 1, ANSWER_TIMEOUT_S * 1000);
        if (ready < 0 && errno == EINTR)
            continue;
        if (ready == 0)
            return vf_fail(VF_EINTERNAL, "the ONNX Runtime worker did not answer in %d s while %s",
                           ANSWER_TIMEOUT_S, doing);
        ssize_t n = recv(ort->channel, p, size, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return worker_gone(ort, doing);
        p += n;
        size -= (size_t)n;
    }
    return VF_OK;
}

static vf_status write_all(vf_ort *ort, const void *buf, size_t size)
{
    const char *p = buf;
    while (size > 0) {
        ssize_t n = send(ort->channel, p, size, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return worker_gone(ort, "receiving a batch");
        p += n;
        size -= (size_t)n;
    }
    return VF_OK;
}

/* One reply: its header and a malloc'd payload (NUL-terminated, for JSON). */
static vf_status read_reply(vf_ort *ort, uint32_t header[4], char **payload, const char *doing)
{
    vf_status status = read_exact(ort, header, 4 * sizeof(uint32_t), doing);
    if (status != VF_OK)
        return status;
    *payload = malloc((size_t)header[1] + 1);
    if (!*payload)
        return vf_fail(VF_EINTERNAL, "out of memory for the worker's reply of %u bytes", header[1]);
    status = read_exact(ort, *payload, header[1], doing);
    (*payload)[header[1]] = '\0';
    if (status != VF_OK) {
        free(*payload);
        *payload = NULL;
    }
    return status;
}

/* The error text of a JSON reply, or NULL when it is not an error. */
static const char *reply_error(json_t *doc)
{
    return json_string_value(json_object_get(doc, "error"));
}

/* Read the graph's input shape from the hello: layout and size. */
static vf_status take_hello(vf_ort *ort, json_t *hello)
{
    snprintf(ort->version, sizeof ort->version, "%s",
             json_string_value(json_object_get(hello, "version")) ?: "?");
    json_t *shape = json_object_get(json_object_get(hello, "input"), "shape");
    if (json_array_size(shape) != 4)
        return vf_fail(VF_EINPUT, "model %s is not an image classifier: its input has %zu "
                                  "dimensions, expected 4 (N,3,S,S or N,S,S,3)",
                       ort->path, json_array_size(shape));
    json_int_t d[4];
    for (int i = 0; i < 4; i++)
        d[i] = json_is_integer(json_array_get(shape, i))
                   ? json_integer_value(json_array_get(shape, i))
                   : -1;
    ort->nhwc = d[3] == 3 && d[1] != 3;
    json_int_t h = ort->nhwc ? d[1] : d[2], w = ort->nhwc ? d[2] : d[3];
    if (h > 0 && h == w && h <= 4096)
        ort->input_size = (int)h;
    return VF_OK;
}

vf_status vf_ort_load(const char *path, vf_ort **out)
{
    char node[VF_PATH_MAX], package[VF_PATH_MAX];
    vf_status status = find_runtime(node, package);
    if (status != VF_OK)
        return status;
    vf_ort *ort = calloc(1, sizeof *ort);
    if (!ort)
        return vf_fail(VF_EINTERNAL, "out of memory");
    ort->pid = -1;
    ort->channel = -1;
    snprintf(ort->path, sizeof ort->path, "%s", path);
    ort->output_fd = memfd_create("vf-ort-output", MFD_CLOEXEC);
    if (ort->output_fd < 0) {
        free(ort);
        return vf_fail(VF_EINTERNAL, "cannot create the worker's log: %s", strerror(errno));
    }
    char threads[16];
    snprintf(threads, sizeof threads, "%d", omp_get_max_threads());
    vf_args args = {0};
    vf_args_add(&args, "-e");
    vf_args_add(&args, vf__ort_worker_script);
    vf_args_add(&args, package);
    vf_args_add(&args, path);
    vf_args_add(&args, threads);
    status = vf_process_start(node, &args, ort->output_fd, &ort->channel, &ort->pid);
    vf_args_free(&args);

    /* The worker's first message says whether the model loaded, and what its input is. */
    uint32_t header[4];
    char *payload = NULL;
    if (status == VF_OK)
        status = read_reply(ort, header, &payload, "loading the model");
    json_t *hello = NULL;
    if (status == VF_OK) {
        hello = header[0] == KIND_JSON ? json_loads(payload, 0, NULL) : NULL;
        if (!hello)
            status = vf_fail(VF_EINTERNAL, "the ONNX Runtime worker sent no hello");
        else if (reply_error(hello))
            status = vf_fail(VF_EINPUT, "model %s is not an ONNX classifier: %s", path,
                             reply_error(hello));
        else
            status = take_hello(ort, hello);
    }
    json_decref(hello);
    free(payload);
    if (status != VF_OK) {
        vf_ort_free(ort);
        return status;
    }
    *out = ort;
    return VF_OK;
}

const char *vf_ort_version(const vf_ort *ort) { return ort->version; }

int vf_ort_input_size(const vf_ort *ort) { return ort->input_size; }

/* NCHW -> NHWC into ort->scratch. */
static const float *to_nhwc(vf_ort *ort, const float *nchw, int n, int size)
{
    size_t plane = (size_t)size * (size_t)size, floats = (size_t)n * 3 * plane;
    if (floats > ort->scratch_floats) {
        float *grown = realloc(ort->scratch, floats * sizeof(float));
        if (!grown)
            return NULL;
        ort->scratch = grown;
        ort->scratch_floats = floats;
    }
    for (int i = 0; i < n; i++)
        for (size_t p = 0; p < plane; p++)
            for (int c = 0; c < 3; c++)
                ort->scratch[(i * plane + p) * 3 + c] = nchw[(i * 3 + c) * plane + p];
    return ort->scratch;
}

vf_status vf_ort_forward(vf_ort *ort, const float *nchw, int n, int size, float *out,
                         int classes)
{
    if (ort->pid < 0)
        return vf_fail(VF_EINTERNAL, "the ONNX Runtime worker of %s has stopped", ort->path);
    size_t floats = (size_t)n * 3 * (size_t)size * (size_t)size;
    const float *input = ort->nhwc ? to_nhwc(ort, nchw, n, size) : nchw;
    if (!input)
        return vf_fail(VF_EINTERNAL, "out of memory for a batch of %d", n);
    uint32_t shape = (uint32_t)size | (ort->nhwc ? 0x80000000u : 0);
    uint32_t request[4] = {REQUEST_MAGIC, (uint32_t)n, (uint32_t)floats, shape};
    vf_status status = write_all(ort, request, sizeof request);
    if (status == VF_OK)
        status = write_all(ort, input, floats * sizeof(float));
    uint32_t header[4];
    char *payload = NULL;
    if (status == VF_OK)
        status = read_reply(ort, header, &payload, "running a batch");
    if (status != VF_OK)
        return status;
    if (header[0] == KIND_JSON) {
        json_t *doc = json_loads(payload, 0, NULL);
        status = vf_fail(VF_EINPUT, "running the model on %d input(s) of %dx%d failed: %s", n,
                         size, size, doc && reply_error(doc) ? reply_error(doc) : payload);
        json_decref(doc);
    } else if (header[0] != KIND_LOGITS || header[2] != (uint32_t)n ||
               (size_t)header[1] != (size_t)n * header[3] * sizeof(float)) {
        status = vf_fail(VF_EINTERNAL, "the ONNX Runtime worker sent a malformed reply");
    } else if (header[3] != (uint32_t)classes) {
        status = vf_fail(VF_EINPUT, "its output has %u values per image, expected %d",
                         header[3], classes);
    } else {
        memcpy(out, payload, header[1]);
    }
    free(payload);
    return status;
}

void vf_ort_free(vf_ort *ort)
{
    if (!ort)
        return;
    if (ort->channel >= 0)
        close(ort->channel); /* the worker exits when its socket closes */
    if (ort->pid >= 0)
        vf_process_finish(ort->pid, 2.0);
    close(ort->output_fd);
    free(ort->scratch);
    free(ort);
}
