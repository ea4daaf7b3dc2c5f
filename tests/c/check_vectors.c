/* The C ABI (capi/include/specfx.h) against a vector directory written by `specfx vectors`:
 * every row's output, probes and per-n constants through specfx_eval, specfx_eval_probes and
 * specfx_constants_of; every row at once through specfx_eval_batch (by pair, and per n with a
 * null n array); the same rows from four threads at once. Prints "N passed, M failed" and
 * exits 0 when nothing failed and every row was checked.
 *
 * Usage: check_vectors VECTOR_DIR */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "specfx.h"

#define MAX_COLS 32

static struct specfx_model *model;
static long rows, ncols, stages;
static int64_t *cells; /* rows x ncols */
static int col_c, col_n, col_slope, col_offset, col_threshold, col_coef, col_depth, col_out;
static int col_probe[SPECFX_MAX_STAGES]; /* d, t, b, sq1.. */
static int n_probes;

static int64_t cell(long r, int col) { return cells[r * ncols + col]; }

static int column(char *names[], const char *want) {
  for (int i = 0; i < ncols; i++)
    if (strcmp(names[i], want) == 0) return i;
  fprintf(stderr, "no column %s\n", want);
  exit(2);
}

static void read_csv(const char *path) {
  FILE *f = fopen(path, "r");
  if (!f) { perror(path); exit(2); }
  static char line[1 << 16];
  char *names[MAX_COLS];
  if (!fgets(line, sizeof line, f)) exit(2);
  line[strcspn(line, "\r\n")] = 0;
  for (char *tok = strtok(line, ","); tok; tok = strtok(NULL, ",")) {
    char *colon = strchr(tok, ':');
    if (colon) *colon = 0;
    names[ncols++] = strdup(tok);
  }
  col_c = column(names, "in_c");
  col_n = column(names, "in_n");
  col_slope = column(names, "in_slope");
  col_offset = column(names, "in_offset");
  col_threshold = column(names, "in_threshold");
  col_coef = column(names, "in_coef");
  col_depth = column(names, "in_depth");
  col_out = column(names, "expected_out");
  for (int i = 0; i < ncols; i++)
    if (strncmp(names[i], "probe_", 6) == 0) col_probe[n_probes++] = i;
  long cap = 1024;
  cells = malloc(sizeof(int64_t) * cap * ncols);
  while (fgets(line, sizeof line, f)) {
    if (rows == cap) { cap *= 2; cells = realloc(cells, sizeof(int64_t) * cap * ncols); }
    char *p = line;
    for (int i = 0; i < ncols; i++) { cells[rows * ncols + i] = strtoll(p, &p, 10); p++; }
    rows++;
  }
  fclose(f);
}

/* Checks every row one by one; returns the number of failures. */
static long check_rows(void) {
  long failed = 0;
  for (long r = 0; r < rows; r++) {
    int64_t c = cell(r, col_c), out = 0, values[SPECFX_MAX_STAGES];
    uint32_t n = (uint32_t)cell(r, col_n);
    uint8_t events[SPECFX_MAX_STAGES];
    int cut, clamped, ok = 1;
    struct specfx_constants k;
    if (specfx_eval(model, c, n, &out) != SPECFX_OK || out != cell(r, col_out)) ok = 0;
    if (specfx_eval_probes(model, c, n, values, events, &cut, &clamped) != SPECFX_OK) ok = 0;
    for (int i = 0; ok && i < n_probes; i++)
      if (values[i] != cell(r, col_probe[i])) ok = 0;
    if (ok && values[stages - 1] != out) ok = 0;
    if (specfx_constants_of(model, n, &k) != SPECFX_OK || k.slope != cell(r, col_slope) ||
        k.offset != cell(r, col_offset) || k.threshold != cell(r, col_threshold) ||
        k.coef != cell(r, col_coef) || (int64_t)k.depth != cell(r, col_depth))
      ok = 0;
    if (!ok) {
      if (failed < 5) fprintf(stderr, "row %ld (c = %lld, n = %u) differs\n", r, (long long)c, n);
      failed++;
    }
  }
  return failed;
}

static void *thread_main(void *arg) {
  *(long *)arg = check_rows();
  return NULL;
}

int main(int argc, char **argv) {
  if (argc != 2) { fprintf(stderr, "usage: check_vectors VECTOR_DIR\n"); return 2; }
  model = specfx_open(argv[1]);
  if (!model) { fprintf(stderr, "specfx_open: %s\n", specfx_last_error()); return 2; }
  stages = specfx_stage_count(model);
  char path[4096];
  snprintf(path, sizeof path, "%s/vectors.csv", argv[1]);
  read_csv(path);
  if (n_probes != stages - 2) { fprintf(stderr, "%d probes for %ld stages\n", n_probes, stages); return 2; }

  long failed = check_rows();

  /* The whole file in one batch, by pair. */
  int64_t *c = malloc(sizeof(int64_t) * rows), *out = malloc(sizeof(int64_t) * rows);
  uint32_t *n = malloc(sizeof(uint32_t) * rows);
  for (long r = 0; r < rows; r++) { c[r] = cell(r, col_c); n[r] = (uint32_t)cell(r, col_n); }
  if (specfx_eval_batch(model, c, n, 0, rows, out) != SPECFX_OK) {
    fprintf(stderr, "specfx_eval_batch: %s\n", specfx_last_error());
    failed++;
  }
  for (long r = 0; r < rows; r++) if (out[r] != cell(r, col_out)) failed++;

  /* Per n, with a null n array: the rows of the first exponent. */
  uint32_t n0 = n[0];
  long m = 0;
  for (long r = 0; r < rows; r++) if (n[r] == n0) c[m++] = c[r];
  if (specfx_eval_batch(model, c, NULL, n0, m, out) != SPECFX_OK) failed++;
  for (long r = 0, i = 0; r < rows; r++)
    if (n[r] == n0 && out[i++] != cell(r, col_out)) failed++;

  /* Four threads evaluating the same model at once. */
  pthread_t t[4];
  long thread_failed[4];
  for (int i = 0; i < 4; i++) pthread_create(&t[i], NULL, thread_main, &thread_failed[i]);
  for (int i = 0; i < 4; i++) { pthread_join(t[i], NULL); failed += thread_failed[i]; }

  specfx_free(model);
  printf("%ld passed, %ld failed\n", rows - (failed > rows ? rows : failed), failed);
  return failed == 0 && rows > 0 ? 0 : 1;
}
