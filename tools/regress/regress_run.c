/* regress_run.c — rendering a suite's cases with sightline-render child processes: see regress.h.
 *
 * At most `jobs` children at once (fork + execv, stdout and stderr to the
 * case's log); a child that outlives its case's timeout is killed (SIGKILL)
 * and the case is an error. One child per case: a crash or a hang in one
 * case cannot take the suite down. Single-threaded (the parent only waits).
 */
#include "regress.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/sl_clock.h"

typedef struct running {
    pid_t pid;
    int index;
    double started_ms;
} running;

/* The argument vector of case c; strings live in buf (kept by the caller). */
static int build_argv(const regress_case *c, const char *render_exe, const char *out_dir, char buf[6][REGRESS_PATH_MAX + 256],
                      char **argv)
{
    int n = 0;
    argv[n++] = (char *)render_exe;
    argv[n++] = c->is_path ? "--path" : "--scene";
    argv[n++] = (char *)c->scene;
    argv[n++] = "--out";
    if (c->is_path) {
        snprintf(buf[0], sizeof buf[0], "%s/new/%s", out_dir, c->name);
        mkdir(buf[0], 0755);
        snprintf(buf[0], sizeof buf[0], "%s/new/%s/%%05d.png", out_dir, c->name);
    } else {
        snprintf(buf[0], sizeof buf[0], "%s/new/%s.png", out_dir, c->name);
    }
    argv[n++] = buf[0];
    argv[n++] = "--samples";
    snprintf(buf[1], sizeof buf[1], "%d", c->limits.samples);
    argv[n++] = buf[1];
    if (c->limits.depth) {
        argv[n++] = "--depth";
        snprintf(buf[2], sizeof buf[2], "%s/new/%s.pfm", out_dir, c->name);
        argv[n++] = buf[2];
    }
    for (int k = 0; k < c->set_count; k++) {
        argv[n++] = "--set";
        argv[n++] = (char *)c->sets[k];
    }
    argv[n] = NULL;
    return n;
}

static pid_t start(const regress_case *c, const char *render_exe, const char *out_dir, regress_result *r)
{
    char buf[6][REGRESS_PATH_MAX + 256], log[REGRESS_PATH_MAX + 256];
    char *argv[16 + 2 * REGRESS_MAX_SETS];
    build_argv(c, render_exe, out_dir, buf, argv);
    snprintf(log, sizeof log, "%s/logs/%s.log", out_dir, c->name);
    int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        r->outcome = REGRESS_ERROR;
        snprintf(r->message, sizeof r->message, "cannot write the log %.400s: %.80s", log, strerror(errno));
        return -1;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
        execv(render_exe, argv);
        fprintf(stderr, "sightline-regress: cannot run %s: %s\n", render_exe, strerror(errno));
        _exit(127);
    }
    close(fd);
    if (pid < 0) {
        r->outcome = REGRESS_ERROR;
        snprintf(r->message, sizeof r->message, "cannot start sightline-render: %s", strerror(errno));
    }
    return pid;
}

/* The last line of the case's log, for an error message. */
static void last_log_line(const char *out_dir, const char *name, char *line, size_t size)
{
    char path[REGRESS_PATH_MAX + 256], buf[512];
    snprintf(path, sizeof path, "%s/logs/%s.log", out_dir, name);
    line[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    while (fgets(buf, sizeof buf, f))
        if (buf[0] && buf[0] != '\n' && strncmp(buf, "sightline: OpenGL renderer", 26) != 0) {
            buf[strcspn(buf, "\n")] = '\0';
            snprintf(line, size, "%.390s", buf);
        }
    fclose(f);
}

static void finish(const regress_suite *s, const char *out_dir, running *run, int status, int timed_out,
                   regress_result *results)
{
    regress_result *r = &results[run->index];
    r->seconds = (sl_clock_ms() - run->started_ms) / 1000.0;
    if (timed_out) {
        r->outcome = REGRESS_ERROR;
        snprintf(r->message, sizeof r->message, "render killed after its timeout of %g s",
                 s->cases[run->index].limits.timeout_s);
    } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        char line[400];
        last_log_line(out_dir, s->cases[run->index].name, line, sizeof line);
        r->outcome = REGRESS_ERROR;
        if (WIFEXITED(status))
            snprintf(r->message, sizeof r->message, "sightline-render exited %d: %s", WEXITSTATUS(status), line);
        else
            snprintf(r->message, sizeof r->message, "sightline-render died of signal %d", WTERMSIG(status));
    }
}

void regress_render_all(const regress_suite *s, const char *render_exe, const char *out_dir, int jobs,
                        regress_result *results)
{
    running *run = calloc((size_t)jobs, sizeof *run);
    if (!run) {
        for (int i = 0; i < s->count; i++) {
            results[i].outcome = REGRESS_ERROR;
            snprintf(results[i].message, sizeof results[i].message, "out of memory");
        }
        return;
    }
    int next = 0, active = 0;
    while (next < s->count || active > 0) {
        while (active < jobs && next < s->count) {
            pid_t pid = start(&s->cases[next], render_exe, out_dir, &results[next]);
            if (pid > 0) {
                for (int j = 0; j < jobs; j++)
                    if (run[j].pid == 0) {
                        run[j] = (running){pid, next, sl_clock_ms()};
                        active++;
                        break;
                    }
            }
            next++;
        }
        for (int j = 0; j < jobs; j++) {
            if (run[j].pid == 0)
                continue;
            int status = 0;
            pid_t done = waitpid(run[j].pid, &status, WNOHANG);
            int timed_out = 0;
            if (done == 0 && sl_clock_ms() - run[j].started_ms > 1000.0 * s->cases[run[j].index].limits.timeout_s) {
                kill(run[j].pid, SIGKILL);
                waitpid(run[j].pid, &status, 0);
                done = run[j].pid;
                timed_out = 1;
            }
            if (done < 0) { /* cannot happen for our own child; never count it as passed */
                results[run[j].index].outcome = REGRESS_ERROR;
                snprintf(results[run[j].index].message, sizeof results[run[j].index].message,
                         "lost the render process: %s", strerror(errno));
                run[j].pid = 0;
                active--;
            } else if (done == run[j].pid) {
                finish(s, out_dir, &run[j], status, timed_out, results);
                run[j].pid = 0;
                active--;
            }
        }
        if (active > 0)
            nanosleep(&(struct timespec){0, 20 * 1000 * 1000}, NULL);
    }
    free(run);
}
