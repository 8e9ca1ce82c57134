/*
 * cdsp_tool.c - the offline tool on saved frames: `cdsp_tool COMMAND ...`
 * dispatches to one subcommand per file (tool_solve.c for solve and
 * overlay, tool_sim.c, tool_export.c, tool_bench.c, and listen.c, which
 * decodes cdspd's UDP stream with the daemon's protocol code). Each has --help.
 */
#include "tool_internal.h"
#include "listen.h"

#include <stdio.h>
#include <string.h>

static const struct {
    const char *name;
    int (*main)(int, char **);
    const char *summary;
} commands[] = {
    {"solve", tool_solve_main, "pipe axes from saved frames, one JSON object per frame"},
    {"overlay", tool_solve_main, "solve, and draw edges, contours and axis over each frame"},
    {"sim", tool_sim_main, "simulated frames of a known pipe, calibration, ground truth"},
    {"export", tool_export_main, "solved pipes as a PLY or OBJ mesh of cylinders"},
    {"bench", tool_bench_main, "the paper's accuracy study on simulated data"},
    {"plot", tool_plot_main, "distance, offset and direction of a run over time, as a PNG"},
    {"compare", tool_compare_main, "errors of solved records against a ground truth"},
    {"listen", cdsp_tool_listen, "decode and print the poses cdspd streams over UDP"},
};

#define N_COMMANDS (sizeof commands / sizeof commands[0])

static void usage(FILE *f)
{
    size_t i;
    fprintf(f,
            "usage: cdsp_tool COMMAND [OPTIONS] [ARGS]\n"
            "\n"
            "Monocular 3D reconstruction of constant-diameter straight pipes (libcdsp %d.%d.%d)\n"
            "on saved frames.\n\nCommands:\n",
            CDSP_VERSION_MAJOR, CDSP_VERSION_MINOR, CDSP_VERSION_PATCH);
    for (i = 0; i < N_COMMANDS; i++)
        fprintf(f, "  %-9s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\n'cdsp_tool COMMAND --help' shows a command's manual; "
               "docs/cdsp_tool.md has them all.\n"
               "Exit status: 0 all done, 1 some input failed, 2 usage or input file error.\n");
}

int main(int argc, char **argv)
{
    size_t i;
    if (argc < 2) {
        usage(stderr);
        return TOOL_EXIT_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        if (argc > 2 && strcmp(argv[1], "help") == 0) {
            for (i = 0; i < N_COMMANDS; i++)
                if (strcmp(argv[2], commands[i].name) == 0) {
                    char *args[] = {argv[2], (char *)"--help", NULL};
                    return commands[i].main(2, args);
                }
        }
        usage(stdout);
        return TOOL_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("cdsp_tool (libcdsp %d.%d.%d)\n", CDSP_VERSION_MAJOR, CDSP_VERSION_MINOR,
               CDSP_VERSION_PATCH);
        return TOOL_EXIT_OK;
    }
    for (i = 0; i < N_COMMANDS; i++)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].main(argc - 1, argv + 1);
    fprintf(stderr, "cdsp_tool: unknown command '%s'\n\n", argv[1]);
    usage(stderr);
    return TOOL_EXIT_USAGE;
}
