/* rangecast stability: the stability cases (tools/common/stability_cases.c,
 * the same code the cmocka suite runs) on each backend, against the float64
 * reference tracer: a table of wrong rays and the largest range error per case
 * and backend. --markdown writes the table docs/stability.md is made from. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accuracy.h"
#include "stability_cases.h"

static void usage(FILE *f)
{
    fprintf(f,
        "Usage: rangecast stability [--backend B[,B...]] [--threads N] [--quick] [--markdown]\n"
        "\n"
        "Runs the stability cases (grazing rays, degenerate triangles, sensors on\n"
        "surfaces, axis-parallel rays, very long and short ranges, scaled instances,\n"
        "far-from-origin maps, coplanar duplicates) on each backend and compares every\n"
        "ray with the float64 reference tracer. A ray is wrong when its class (return,\n"
        "+inf, -inf) differs, its range error passes the case's tolerance, an output is\n"
        "NaN, its normal is not unit or not perpendicular to the face, it hits a\n"
        "zero-area triangle, or (coplanar case) its ids are not the smallest key.\n"
        "\n"
        "Options:\n"
        "  --backend LIST   comma-separated: bvh, embree, vulkan, auto (the one auto picks);\n"
        "                   vulkan-rq: vulkan with its ray query traversal (RC_CONTEXT_VULKAN_RAY_QUERY)\n"
        "                   (default: every backend built in)\n"
        "  --threads N      library threads (default 2)\n"
        "  --quick          the smaller sizes the sanitizer runs use\n"
        "  --markdown       a Markdown table (with the case descriptions) instead of text\n"
        "Exit status: 0 when no ray is wrong, 1 when some are (or a case failed to run), 2 bad arguments.\n");
}

int rcp_cmd_stability(int argc, char **argv)
{
    const char *cmd = "stability";
    uint32_t backends[4], flags[4] = {0, 0, 0, 0}, nb = 0, threads = 2, b;
    const char *names[4];
    int markdown = 0, quick = 0, listed = 0, i, r, c, any_wrong = 0;
    static rcu_stab_result results[4][RCU_STAB_CASE_COUNT];
    int ran[4][RCU_STAB_CASE_COUNT];
    for (i = 1; i < argc; i++) {
        const char *v = NULL;
        if (rcp_is_help(argv[i])) {
            usage(stdout);
            return RCP_EXIT_OK;
        }
        if ((r = rcp_opt(argc, argv, &i, "--backend", &v)) != 0) {
            char buf[128], *tok, *save = NULL;
            if (r < 0) return RCP_EXIT_USAGE;
            snprintf(buf, sizeof buf, "%s", v);
            listed = 1;
            for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
                if (nb == 4) return rcp_usage_error(cmd, "--backend: at most 4 backends");
                if (strcmp(tok, "vulkan-rq") == 0) {
                    backends[nb] = RC_BACKEND_VULKAN;
                    flags[nb] = RC_CONTEXT_VULKAN_RAY_QUERY;
                } else if (rcp_parse_backend(cmd, tok, &backends[nb]) != 0) {
                    return RCP_EXIT_USAGE;
                }
                nb++;
            }
        } else if ((r = rcp_opt_threads(cmd, argc, argv, &i, &threads)) != 0) {
            if (r < 0) return RCP_EXIT_USAGE;
        } else if (strcmp(argv[i], "--markdown") == 0) {
            markdown = 1;
        } else if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else {
            return rcp_usage_error(cmd, "unknown argument '%s'", argv[i]);
        }
    }
    if (listed && nb == 0) return rcp_usage_error(cmd, "--backend: expected a list of backends, got an empty one");
    /* auto runs (and is reported as) the backend the library picks for it */
    for (b = 0; b < nb; b++)
        if (backends[b] == RC_BACKEND_AUTO) {
            rcp_world w;
            if (rcp_world_create(cmd, RC_BACKEND_AUTO, 1, NULL, NULL, 0, &w) != RCP_EXIT_OK) return RCP_EXIT_FAIL;
            backends[b] = w.backend;
            rcp_world_destroy(&w);
        }
    if (nb == 0) {
        static const uint32_t all[3] = {RC_BACKEND_BVH, RC_BACKEND_EMBREE, RC_BACKEND_VULKAN};
        for (b = 0; b < 3; b++)
            if (rc_backend_available(all[b])) backends[nb++] = all[b];
    }
    for (b = 0; b < nb; b++) names[b] = flags[b] ? "vulkan-rq" : rc_backend_name(backends[b]);
    for (b = 0; b < nb; b++)
        for (c = 0; c < RCU_STAB_CASE_COUNT; c++) {
            rcu_stab_options opt;
            memset(&opt, 0, sizeof opt);
            opt.backend = backends[b];
            opt.context_flags = flags[b];
            opt.threads = threads;
            opt.quick = quick;
            ran[b][c] = rcu_stab_run(c, &opt, &results[b][c]) == 0;
            if (!ran[b][c]) {
                fprintf(stderr, "rangecast stability: %s on %s: %s\n", rcu_stab_case_name(c), names[b],
                        results[b][c].note);
                any_wrong = 1;
            } else if (results[b][c].wrong) {
                any_wrong = 1;
            }
        }
    if (markdown) {
        printf("| case |");
        for (b = 0; b < nb; b++) printf(" %s: wrong / rays | %s: max error [m] |", names[b], names[b]);
        printf(" tolerance |\n|---|");
        for (b = 0; b < nb; b++) printf("---:|---:|");
        printf("---|\n");
    } else {
        printf("%-16s", "case");
        for (b = 0; b < nb; b++) printf(" %10s wrong/rays %10s", names[b], "max err");
        printf("  tolerance\n");
    }
    for (c = 0; c < RCU_STAB_CASE_COUNT; c++) {
        char tol[48];
        snprintf(tol, sizeof tol, "%g m + %g x range", results[0][c].tol_abs, results[0][c].tol_rel);
        printf(markdown ? "| %s |" : "%-16s", rcu_stab_case_name(c));
        for (b = 0; b < nb; b++) {
            const rcu_stab_result *s = &results[b][c];
            char wr[48];
            if (!ran[b][c]) snprintf(wr, sizeof wr, "error");
            else snprintf(wr, sizeof wr, "%llu / %llu", (unsigned long long)s->wrong, (unsigned long long)s->rays);
            if (markdown) printf(" %s | %.3g |", wr, s->max_err);
            else printf(" %21s %10.3g", wr, s->max_err);
        }
        printf(markdown ? " %s |\n" : "  %s\n", tol);
    }
    if (markdown) {
        printf("\nCases:\n\n");
        for (c = 0; c < RCU_STAB_CASE_COUNT; c++) printf("- **%s**: %s.\n", rcu_stab_case_name(c), rcu_stab_case_about(c));
    }
    /* the first wrong ray of each failing cell */
    for (b = 0; b < nb; b++)
        for (c = 0; c < RCU_STAB_CASE_COUNT; c++) {
            const rcu_stab_result *s = &results[b][c];
            if (ran[b][c] && s->wrong)
                printf(markdown ? "\n- %s / %s: %llu wrong (class %llu, range %llu, NaN %llu, normals %llu, "
                                  "zero-area hits %llu, ids %llu); first: %s\n"
                                : "%s/%s: %llu wrong (class %llu, range %llu, NaN %llu, normals %llu, "
                                  "zero-area hits %llu, ids %llu); first: %s\n",
                       names[b], rcu_stab_case_name(c), (unsigned long long)s->wrong,
                       (unsigned long long)s->class_mismatch, (unsigned long long)s->range_errors,
                       (unsigned long long)s->nan_outputs, (unsigned long long)s->bad_normals,
                       (unsigned long long)s->degenerate_hits, (unsigned long long)s->key_mismatch, s->note);
        }
    return any_wrong ? RCP_EXIT_FAIL : RCP_EXIT_OK;
}
