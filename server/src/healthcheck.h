/* healthcheck.h - `kmorphd --healthcheck URL`: one GET, exit 0 on 200. */
#ifndef SRV_HEALTHCHECK_H
#define SRV_HEALTHCHECK_H

#include <stdbool.h>
#include <stdio.h>

/* Seconds the whole check may take: connect, send, first line back. A
 * container engine's health check times out at 3 s by default (Docker's
 * --timeout below is that), so an answer later than this is a failure
 * either way. */
#define SRV_HEALTHCHECK_SECONDS 3

/* Whether arg (argv[1]) asks for the health check mode: "--healthcheck"
 * or "--healthcheck=URL". */
bool srv_healthcheck_requested(const char *arg);

/* srv_healthcheck_main - the health check mode, from main's argv: GET the
 * URL given as `--healthcheck URL` or `--healthcheck=URL` (http://host
 * [:port][/path], host a name, an IPv4 address or a bracketed IPv6 one;
 * port 80 and path / when left out) over a fresh TCP connection, within
 * SRV_HEALTHCHECK_SECONDS. Returns the exit status: 0 when the status
 * line says 200, 1 when it says anything else or nothing came (refused,
 * timed out, not HTTP), 2 for a URL it cannot use (a message on err). */
int srv_healthcheck_main(int argc, char **argv, FILE *err);

#endif
