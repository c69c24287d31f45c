/* test_server_catalog.c — `sightline-server catalog ...` and the catalog's rules.
 *
 * In a temporary directory: a tiny NRRD volume inside the data directory is
 * added (exit 0) and listed with its kind and dims; adding it again, adding
 * a file outside the data directory, and adding one through a symlink that
 * leaves it are refused (non-zero exit, nothing listed); scan registers the
 * files it can load (an LR-spline volume among them, listed as lr_volume
 * with its element and basis counts) and skips the rest; remove deletes exactly one name and
 * refuses an unknown one; add-generator validates its JSON; names with SQL
 * quotes are data, not SQL (bound parameters); the database is in WAL mode
 * (a -wal file exists while the server holds it); bad server arguments exit 2.
 * Removal sticks: a removed built-in or sample is not registered again by
 * later starts (`list` runs the same registration as a server start) until
 * `add-builtins` or `scan` brings it back; options may precede `catalog`.
 * The same server run also checks --max-clients: the third upgrade is refused
 * and a slot frees when a client leaves.
 */
#include "sl_server_harness.h"
#include "sl_test.h"

static char exe[1024], dir[256], db[320], data[320];

/* Runs the server binary with args (NULL-terminated), stdout to out_path; returns the exit status. */
static int run(const char *out_path, const char *const *args)
{
    const char *argv[32] = {exe};
    int n = 1;
    for (int i = 0; args[i] && n < 28; i++)
        argv[n++] = args[i];
    argv[n++] = "--db";
    argv[n++] = db;
    argv[n++] = "--data-dir";
    argv[n++] = data;
    argv[n] = NULL;
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(out_path ? out_path : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0)
            dup2(fd, 1);
        int devnull = open("/dev/null", O_WRONLY);
        if (devnull >= 0)
            dup2(devnull, 2);
        execv(exe, (char *const *)argv);
        _exit(127);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static char listing[16384];

static const char *list(void)
{
    char out[400];
    snprintf(out, sizeof out, "%s/list.txt", dir);
    const char *args[] = {"catalog", "list", NULL};
    listing[0] = 0;
    if (run(out, args) != 0)
        return listing;
    FILE *f = fopen(out, "r");
    size_t n = f ? fread(listing, 1, sizeof listing - 1, f) : 0;
    listing[n] = 0;
    if (f)
        fclose(f);
    return listing;
}

static int write_nrrd(const char *path)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    fprintf(f, "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 3 2\nencoding: raw\n\n");
    for (int i = 0; i < 24; i++)
        fputc(i * 10, f);
    fclose(f);
    return 0;
}

int main(void)
{
    const char *bin = getenv("SIGHTLINE_BINARY_DIR");
    snprintf(exe, sizeof exe, "%s/bin/sightline-server", bin ? bin : "build");
    snprintf(dir, sizeof dir, "/tmp/sl-server-test-XXXXXX");
    SL_CHECK(mkdtemp(dir) != NULL);
    snprintf(db, sizeof db, "%s/catalog.db", dir);
    snprintf(data, sizeof data, "%s/data", dir);
    mkdir(data, 0755);
    char inside[400], outside[400], link[400], junk[400];
    snprintf(inside, sizeof inside, "%s/vol.nrrd", data);
    snprintf(outside, sizeof outside, "%s/outside.nrrd", dir);
    snprintf(link, sizeof link, "%s/link.nrrd", data);
    snprintf(junk, sizeof junk, "%s/junk.nrrd", data);
    SL_CHECK(write_nrrd(inside) == 0 && write_nrrd(outside) == 0);
    SL_CHECK(symlink(outside, link) == 0);

    /* Built-ins are registered on first use. */
    SL_CHECK(strstr(list(), "tornado ") != NULL && strstr(listing, "head ") != NULL);

    const char *add_inside[] = {"catalog", "add", inside, NULL};
    SL_CHECK(run(NULL, add_inside) == 0);
    SL_CHECK(strstr(list(), "vol.nrrd") != NULL && strstr(listing, "\"dims\":[4,3,2]") != NULL);
    SL_CHECK(run(NULL, add_inside) != 0); /* duplicate name */

    const char *add_outside[] = {"catalog", "add", outside, NULL};
    SL_CHECK(run(NULL, add_outside) != 0);
    const char *add_link[] = {"catalog", "add", link, NULL};
    SL_CHECK(run(NULL, add_link) != 0);
    char dotdot[500];
    snprintf(dotdot, sizeof dotdot, "%s/../outside.nrrd", data);
    const char *add_dotdot[] = {"catalog", "add", dotdot, NULL};
    SL_CHECK(run(NULL, add_dotdot) != 0);
    SL_CHECK(strstr(list(), "outside.nrrd") == NULL && strstr(listing, "link.nrrd") == NULL);

    /* scan: loads what it can (a second volume), skips the unloadable and the escaping link. */
    char second[400];
    snprintf(second, sizeof second, "%s/second.nrrd", data);
    SL_CHECK(write_nrrd(second) == 0);
    FILE *f = fopen(junk, "w");
    if (f) {
        fputs("not a nrrd file\n", f);
        fclose(f);
    }
    /* An LR-spline volume (the loader's seed file) is scanned too and listed as lr_volume. */
    char lr_path[400];
    snprintf(lr_path, sizeof lr_path, "%s/refined.lr", data);
    FILE *src = fopen("tests/fuzz/corpus/lr/refined.lr", "rb"), *dst = fopen(lr_path, "wb");
    SL_CHECK(src && dst);
    for (int ch; src && dst && (ch = fgetc(src)) != EOF;)
        fputc(ch, dst);
    if (src)
        fclose(src);
    if (dst)
        fclose(dst);
    const char *scan[] = {"catalog", "scan", data, NULL};
    SL_CHECK(run(NULL, scan) == 0);
    SL_CHECK(strstr(list(), "second.nrrd") != NULL && strstr(listing, "junk.nrrd") == NULL &&
             strstr(listing, "link.nrrd") == NULL);
    SL_CHECK_MSG(strstr(listing, "refined.lr") && strstr(listing, "lr_volume") &&
                 strstr(listing, "\"elements\":5") && strstr(listing, "\"basis_functions\":13"),
                 "LR volume not listed: %.2000s", listing);
    const char *scan_out[] = {"catalog", "scan", "/etc", NULL};
    SL_CHECK(run(NULL, scan_out) != 0);

    /* add-generator validates; quotes in names are data. */
    const char *gen_ok[] = {"catalog", "add-generator", "it's \"quoted\"; DROP TABLE datasets;--",
                            "{\"generator\":\"tornado\",\"lines\":5,\"points\":10}", NULL};
    SL_CHECK(run(NULL, gen_ok) == 0);
    SL_CHECK(strstr(list(), "it's \"quoted\"; DROP TABLE datasets;--") != NULL && strstr(listing, "vol.nrrd") != NULL);
    const char *gen_bad[] = {"catalog", "add-generator", "bad", "{\"generator\":\"tornado\",\"lines\":-5}", NULL};
    SL_CHECK(run(NULL, gen_bad) != 0);
    SL_CHECK(strstr(list(), "bad ") == NULL);

    /* remove */
    const char *rm[] = {"catalog", "remove", "vol.nrrd", NULL};
    SL_CHECK(run(NULL, rm) == 0);
    SL_CHECK(strstr(list(), "vol.nrrd") == NULL && strstr(listing, "second.nrrd") != NULL);
    SL_CHECK(run(NULL, rm) != 0);

    /* A removed built-in stays removed across starts; add-builtins brings it back. */
    const char *rm_tornado[] = {"catalog", "remove", "tornado", NULL};
    SL_CHECK(run(NULL, rm_tornado) == 0);
    SL_CHECK(strstr(list(), "tornado ") == NULL && strstr(listing, "head ") != NULL);
    SL_CHECK(strstr(list(), "tornado ") == NULL);
    const char *builtins[] = {"catalog", "add-builtins", NULL};
    SL_CHECK(run(NULL, builtins) == 0);
    SL_CHECK(strstr(list(), "tornado ") != NULL);

    /* Samples are registered at start; a removed sample stays removed until a scan. */
    char samples[400], sample[500];
    snprintf(samples, sizeof samples, "%s/samples", data);
    snprintf(sample, sizeof sample, "%s/sample.nrrd", samples);
    SL_CHECK(mkdir(samples, 0755) == 0 && write_nrrd(sample) == 0);
    SL_CHECK(strstr(list(), "sample.nrrd") != NULL);
    const char *rm_sample[] = {"catalog", "remove", "sample.nrrd", NULL};
    SL_CHECK(run(NULL, rm_sample) == 0);
    SL_CHECK(strstr(list(), "sample.nrrd") == NULL);
    SL_CHECK(strstr(list(), "sample.nrrd") == NULL);
    const char *scan_samples[] = {"catalog", "scan", samples, NULL};
    SL_CHECK(run(NULL, scan_samples) == 0);
    SL_CHECK(strstr(list(), "sample.nrrd") != NULL);

    /* Global options before the subcommand. */
    {
        char out[400];
        snprintf(out, sizeof out, "%s/pre.txt", dir);
        pid_t pid = fork();
        if (pid == 0) {
            int fd = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (fd >= 0)
                dup2(fd, 1);
            execl(exe, exe, "--db", db, "--data-dir", data, "catalog", "list", (char *)NULL);
            _exit(127);
        }
        int status = 0;
        waitpid(pid, &status, 0);
        SL_CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "--db X catalog list exit status %d", status);
        char text[16384] = "";
        FILE *pf = fopen(out, "r");
        size_t n = pf ? fread(text, 1, sizeof text - 1, pf) : 0;
        text[n] = 0;
        if (pf)
            fclose(pf);
        SL_CHECK(strstr(text, "second.nrrd") != NULL);
    }
    const char *stray[] = {"list", "catalog", NULL};
    SL_CHECK(run(NULL, stray) == 2);

    /* WAL mode: the server keeps a -wal file beside the database. */
    char wal[400];
    snprintf(wal, sizeof wal, "%s-wal", db);
    const char *bad_port[] = {"--port", "notaport", NULL};
    SL_CHECK(run(NULL, bad_port) == 2);
    const char *bad_cmd[] = {"catalog", "frobnicate", NULL};
    SL_CHECK(run(NULL, bad_cmd) == 2);
    harness h;
    const char *cap[] = {"--max-clients", "2", NULL};
    if (harness_start(&h, cap) == 0) {
        char hwal[400];
        snprintf(hwal, sizeof hwal, "%s-wal", h.db);
        SL_CHECK(access(hwal, F_OK) == 0);
        tclient c1, c2, c3;
        SL_CHECK(tclient_connect(&c1, h.port, NULL) == 0 && tclient_hello(&c1, NULL, NULL, 32, 32) == 0);
        SL_CHECK(tclient_connect(&c2, h.port, NULL) == 0 && tclient_hello(&c2, NULL, NULL, 32, 32) == 0);
        SL_CHECK(tclient_connect(&c3, h.port, NULL) != 0);
        tclient_close(&c3);
        tclient_close(&c1);
        int ok = 0;
        for (int i = 0; i < 50 && !ok; i++) { /* the server notices the close asynchronously */
            ok = tclient_connect(&c3, h.port, NULL) == 0;
            if (!ok) {
                tclient_close(&c3);
                usleep(100000);
            }
        }
        SL_CHECK(ok && tclient_hello(&c3, NULL, NULL, 32, 32) == 0);
        tclient_close(&c3);
        tclient_close(&c2);
    } else {
        SL_CHECK(!"server started");
    }
    SL_CHECK(harness_stop(&h) == 0);

    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    SL_CHECK(system(cmd) == 0);
    SL_TEST_END();
}
