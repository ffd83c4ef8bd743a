/* child_program.c - the child tests/test_platform.c starts through the
 * process seam (platform/process.h), on every OS. Each argument is one
 * step: "out:TEXT" and "err:TEXT" write a line to stdout or stderr,
 * "bytes:N" writes N letters ('a' + i % 26: no line ends, which a
 * Windows text stream would rewrite) to stdout, "exit:CODE" ends with
 * that code, "hang" waits forever (to be killed). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strncmp(a, "out:", 4)) {
            printf("%s\n", a + 4);
            fflush(stdout);
        } else if (!strncmp(a, "err:", 4)) {
            fprintf(stderr, "%s\n", a + 4);
            fflush(stderr);
        } else if (!strncmp(a, "bytes:", 6)) {
            const long n = strtol(a + 6, NULL, 10);
            for (long k = 0; k < n; k++) putchar('a' + (int)(k % 26));
            fflush(stdout);
        } else if (!strncmp(a, "exit:", 5)) {
            return atoi(a + 5);
        } else if (!strcmp(a, "hang")) {
            for (;;) getchar(); /* stdin is empty: on POSIX EOF at once, so spin on it */
        }
    }
    return 0;
}
