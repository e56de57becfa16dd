/*
 * regression_driver — runs a fuzz target over files instead of under
 * libFuzzer (the pattern of zstd's tests/fuzz/regression_driver.c), so that
 * every compiler builds the targets and ctest replays the committed corpus.
 *
 *   fuzz_select_regression FILE_OR_DIRECTORY...
 *
 * Directories are read one level deep, files in name order so that runs are
 * reproducible. A broken guarantee aborts inside the target; the driver
 * itself fails when an input cannot be read, when an input runs for longer
 * than INPUT_SECONDS (libFuzzer's -timeout: a call that never returns), or
 * when it was given no input at all (an empty corpus must not pass silently).
 */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Wall-clock seconds one input may take; inputs take milliseconds, and about
 * fifty times that under valgrind. */
#define INPUT_SECONDS 20u

/* The input being run, for the message when it takes too long. */
static const char *volatile current_input = "";

static void too_long(int sig) {
    static const char msg[] = "regression_driver: an input ran for too long (a hang): ";
    const char *name = current_input;
    (void)sig;
    if (write(2, msg, sizeof msg - 1) < 0 || write(2, name, strlen(name)) < 0 ||
        write(2, "\n", 1) < 0)
        _exit(2);
    _exit(1);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Reads a whole file; NULL on failure. *size may be 0 (malloc(1) then). */
static uint8_t *read_file(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    uint8_t *buf = NULL;
    long len;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        buf = (uint8_t *)malloc((size_t)len + 1u);
        if (buf && fread(buf, 1, (size_t)len, f) != (size_t)len) {
            free(buf);
            buf = NULL;
        }
        *size = (size_t)len;
    }
    fclose(f);
    return buf;
}

static int run_file(const char *path) {
    size_t size = 0;
    uint8_t *data = read_file(path, &size);
    if (!data) {
        fprintf(stderr, "regression_driver: cannot read %s\n", path);
        return 0;
    }
    current_input = path;
    alarm(INPUT_SECONDS);
    LLVMFuzzerTestOneInput(data, size);
    alarm(0);
    free(data);
    return 1;
}

static int compare_names(const void *a, const void *b) {
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Runs every regular file of a directory in name order; returns the count,
 * or -1 on an error. */
static long run_directory(const char *dir) {
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL;
    size_t count = 0, cap = 0, i;
    long done = 0;
    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL) {
        size_t len;
        if (e->d_name[0] == '.')
            continue;
        if (count == cap) {
            char **grown = (char **)realloc(names, (cap ? cap * 2 : 64) * sizeof *names);
            if (!grown)
                break;
            names = grown;
            cap = cap ? cap * 2 : 64;
        }
        len = strlen(dir) + strlen(e->d_name) + 2;
        names[count] = (char *)malloc(len);
        if (!names[count])
            break;
        snprintf(names[count], len, "%s/%s", dir, e->d_name);
        count++;
    }
    closedir(d);
    qsort(names, count, sizeof *names, compare_names);
    for (i = 0; i < count; ++i) {
        struct stat st;
        if (done >= 0 && stat(names[i], &st) == 0 && S_ISREG(st.st_mode))
            done = run_file(names[i]) ? done + 1 : -1;
        free(names[i]);
    }
    free(names);
    return done;
}

int main(int argc, char **argv) {
    long inputs = 0;
    int i;
    signal(SIGALRM, too_long);
    for (i = 1; i < argc; ++i) {
        struct stat st;
        if (stat(argv[i], &st) != 0) {
            fprintf(stderr, "regression_driver: %s does not exist\n", argv[i]);
            return 1;
        }
        if (S_ISDIR(st.st_mode)) {
            long n = run_directory(argv[i]);
            if (n < 0) {
                fprintf(stderr, "regression_driver: cannot read the directory %s\n", argv[i]);
                return 1;
            }
            inputs += n;
        } else if (run_file(argv[i])) {
            inputs++;
        } else {
            return 1;
        }
    }
    if (inputs == 0) {
        fprintf(stderr, "regression_driver: no inputs\n");
        return 1;
    }
    printf("regression_driver: %ld inputs passed\n", inputs);
    return 0;
}
