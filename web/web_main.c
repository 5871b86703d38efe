/* web_main.c: bin/hexcnc-web, the program behind `hexcnc web`: the operator's station in the
 * browser (docs/ui.md). A program of its own because civetweb's worker threads have a small
 * fixed stack, and the thread-local storage of Ceres' libraries, which bin/hexcnc links for
 * `hexcnc calibrate`, takes it: a 404 answer overflowed it. */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/prctl.h>
#include <unistd.h>

#include "common/config.h"
#include "web/web.h"

static const char usage[] =
    "web [--listen ADDRESS:PORT] [--socket PATH] [--quiet] [--exit-with-parent] CONFIG.ini   serve the operator's "
    "station for the machine session (docs/ui.md)";

static volatile sig_atomic_t web_stop;

static void web_on_signal(int sig)
{
    (void)sig;
    web_stop = 1;
}

int main(int argc, char **argv)
{
    const char *ini_path = NULL, *listen = NULL, *sock = NULL;
    bool quiet = false, with_parent = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            printf("usage: hexcnc %s\n", usage);
            return 0;
        }
        if (!strcmp(argv[i], "--quiet"))
            quiet = true;
        else if (!strcmp(argv[i], "--exit-with-parent"))
            with_parent = true;
        else if (!strcmp(argv[i], "--listen") && i + 1 < argc)
            listen = argv[++i];
        else if (!strcmp(argv[i], "--socket") && i + 1 < argc)
            sock = argv[++i];
        else if (argv[i][0] == '-' || ini_path) {
            fprintf(stderr, "usage: hexcnc %s\n", usage);
            return 2;
        } else
            ini_path = argv[i];
    }
    if (!ini_path) {
        fprintf(stderr, "usage: hexcnc %s\n", usage);
        return 2;
    }
    struct inifile ini = { 0 };
    char err[1536];
    if (config_load(&ini, ini_path, err, sizeof err) != CONFIG_OK) {
        fprintf(stderr, "hexcnc web: %s\n", err);
        return 1;
    }
    struct web_config c;
    int rc = 1;
    if (web_config_read(&c, &ini, listen, sock, err, sizeof err)) {
        fprintf(stderr, "hexcnc web: %s: %s\n", ini_path, err);
        goto out;
    }
    /* started beside the session (scripts/hexcnc-start): ends when it does */
    pid_t parent = getppid();
    if (with_parent && (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != parent))
        goto out;
    struct sigaction sa = { .sa_handler = web_on_signal };
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    if (web_serve(&c, &web_stop, quiet, err, sizeof err)) {
        fprintf(stderr, "hexcnc web: %s\n", err);
        goto out;
    }
    rc = 0;
out:
    inifile_free(&ini);
    return rc;
}
