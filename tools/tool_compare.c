/*
 * tool_compare.c - `cdsp_tool compare`: solved records against a ground
 * truth (sim's truth.json, or any file of that shape a user makes from a
 * reference): per frame the paper's axis RMSE (docs/method.md section 8,
 * Eq. 17-21: RMS distance of points of the found visible axis segment from
 * the true axis), the angle between the directions and the distance error,
 * then a summary over the frames.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char compare_description[] =
    "    Reads the records of `cdsp_tool solve` (JSON Lines or --csv; \"-\" is\n"
    "    standard input) or of `cdspd --format json`, and the ground truth TRUTH:\n"
    "    the truth.json that `cdsp_tool sim` writes beside its frames, or a file\n"
    "    of the same shape ({\"frames\": [{\"file\", \"point\", \"direction\",\n"
    "    \"distance\", \"half_length\"}, ...]}) made from a reference measurement.\n"
    "    A record is matched to the truth frame of the same file name (\"file\"),\n"
    "    else to the truth frame at the same position.\n"
    "\n"
    "    For each record it prints the paper's accuracy metric (Yao et al. 2024,\n"
    "    Eq. 17-21): the RMS distance of --samples points evenly spaced along the\n"
    "    visible axis segment the record reports from the true axis (when the\n"
    "    record has no extent, a segment of the true half length around P_C);\n"
    "    the angle between the found and the true direction, in degrees; and\n"
    "    the distance error |P_C| found minus true. Lengths are in the unit of\n"
    "    the radius (mm in the examples). Then one summary line: frames, solved,\n"
    "    failed, and over the solved frames the RMS and the largest of each\n"
    "    error (the mean as well for the signed distance error).\n\n";

static const char compare_after[] =
    "OUTPUT\n"
    "    A table on standard output, one line per record, then the summary:\n"
    "      file       the record's frame file (its \"frame\" number if it has none)\n"
    "      status     ok, or the record's error token (no-pipe, bad-frame, ...),\n"
    "                 or no-truth when TRUTH has no frame for it\n"
    "      rmse       the paper's axis RMSE\n"
    "      angle_deg  angle between the directions, degrees\n"
    "      d_error    distance error, found - true\n"
    "    With --json: one JSON object per record with those keys (numbers only\n"
    "    for ok records), then {\"summary\": {\"frames\", \"solved\", \"failed\",\n"
    "    \"no_truth\", \"rmse_rms\", \"rmse_max\", \"angle_rms_deg\",\n"
    "    \"angle_max_deg\", \"d_error_mean\", \"d_error_rms\", \"d_error_max\"}}.\n"
    "\n"
    "EXAMPLES\n"
    "    cdsp_tool sim --out sim1 --frames 20 --move 1,0,0 --noise 0.02\n"
    "    cdsp_tool solve --calib sim1/camera.yaml --radius 8 sim1 > poses.jsonl\n"
    "    cdsp_tool compare poses.jsonl sim1/truth.json\n"
    "    cdsp_tool compare --max-rmse 0.1 --json poses.jsonl sim1/truth.json\n";

static const char compare_exit[] =
    "    0  every record was solved and compared (and within --max-rmse)\n"
    "    1  some record failed, had no truth frame, or exceeded --max-rmse\n"
    "    2  usage error, or a records or truth file that cannot be read (the\n"
    "       message names the file and line)\n";

typedef struct {
    double sum2, max, sum;
    int n;
} stat;

static void stat_add(stat *s, double v)
{
    s->sum2 += v * v;
    s->sum += v;
    if (fabs(v) > s->max)
        s->max = fabs(v);
    s->n++;
}

static double stat_rms(const stat *s)
{
    return s->n ? sqrt(s->sum2 / s->n) : NAN;
}

int tool_compare_main(int argc, char **argv)
{
    static const tool_doc doc = {
        "compare", "errors of solved records against a ground truth",
        "[OPTIONS] RECORDS.jsonl|RECORDS.csv|- TRUTH.json", compare_description, compare_after,
        compare_exit};
    char **pos = NULL;
    int npos = 0, rc, json = 0, samples = 100, failed = 0, no_truth = 0, over = 0;
    double max_rmse = 0;
    tool_records rs;
    tool_truth t;
    stat s_rmse = {0, 0, 0, 0}, s_angle = {0, 0, 0, 0}, s_dist = {0, 0, 0, 0};
    size_t i;
    int width = 5;
    const tool_opt opts[] = {
        {"json", 0, OPT_FLAG, &json, 0, 0, NULL,
         "JSON Lines instead of the table (see OUTPUT).", NULL, 0},
        {"samples", 0, OPT_INT, &samples, 2, 100000, "N",
         "Points along the segment for the axis RMSE (the paper's metric).", NULL, 0},
        {"max-rmse", 0, OPT_REAL, &max_rmse, 0, 1e12, "E",
         "Exit with status 1 when a frame's axis RMSE exceeds E (unit of R); 0: no "
         "bound.", NULL, 0},
        {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
    };
    rc = tool_parse_alloc("compare", &doc, opts, argc, argv, &pos, &npos);
    if (rc)
        return rc - 1;
    if (npos != 2) {
        free(pos);
        return tool_usage_error("compare", "expected RECORDS and TRUTH.json (see --help)");
    }
    rc = tool_records_read("compare", pos[0], &rs);
    if (rc) {
        free(pos);
        return rc;
    }
    rc = tool_truth_read("compare", pos[1], &t);
    if (rc) {
        tool_records_free(&rs);
        free(pos);
        return rc;
    }
    for (i = 0; i < rs.n; i++) {
        int w = rs.r[i].frame ? (int)strlen(rs.r[i].frame) : 4;
        width = w > width ? w : width;
    }
    if (width > 60)
        width = 60;
    if (!json)
        printf("%-*s  %-10s %10s %10s %10s\n", width, "file", "status", "rmse", "angle_deg",
               "d_error");
    for (i = 0; i < rs.n; i++) {
        const tool_record *r = &rs.r[i];
        const tool_truth_frame *tf = tool_truth_match(&t, r, i);
        const char *frame = r->frame ? r->frame : "-";
        const char *status = !tf ? "no-truth" : r->ok ? "ok" : r->error;
        double rmse = NAN, angle = NAN, dd = NAN;
        if (!tf)
            no_truth++;
        else if (!r->ok)
            failed++;
        else {
            tool_record_errors(r, tf, samples, &rmse, &angle, &dd);
            stat_add(&s_rmse, rmse);
            stat_add(&s_angle, angle);
            stat_add(&s_dist, dd);
            over |= max_rmse > 0 && rmse > max_rmse;
        }
        if (json) {
            char buf[8192];
            cdsp_host_json j;
            cdsp_host_json_init(&j, buf, sizeof buf);
            cdsp_host_json_begin_object(&j);
            cdsp_host_json_key(&j, "file");
            cdsp_host_json_string(&j, frame);
            cdsp_host_json_key(&j, "status");
            cdsp_host_json_string(&j, status);
            if (isfinite(rmse)) {
                cdsp_host_json_key(&j, "rmse");
                cdsp_host_json_number(&j, rmse);
                cdsp_host_json_key(&j, "angle_deg");
                cdsp_host_json_number(&j, angle);
                cdsp_host_json_key(&j, "d_error");
                cdsp_host_json_number(&j, dd);
            }
            cdsp_host_json_end_object(&j);
            if (cdsp_host_json_finish(&j))
                printf("%s\n", buf);
        } else if (isfinite(rmse)) {
            printf("%-*s  %-10s %10.4f %10.4f %+10.4f\n", width, frame, status, rmse, angle, dd);
        } else {
            printf("%-*s  %-10s %10s %10s %10s\n", width, frame, status, "-", "-", "-");
        }
    }
    if (json) {
        char buf[2048];
        cdsp_host_json j;
        cdsp_host_json_init(&j, buf, sizeof buf);
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "summary");
        cdsp_host_json_begin_object(&j);
        cdsp_host_json_key(&j, "frames");
        cdsp_host_json_int(&j, (long long)rs.n);
        cdsp_host_json_key(&j, "solved");
        cdsp_host_json_int(&j, s_rmse.n);
        cdsp_host_json_key(&j, "failed");
        cdsp_host_json_int(&j, failed);
        cdsp_host_json_key(&j, "no_truth");
        cdsp_host_json_int(&j, no_truth);
        cdsp_host_json_key(&j, "rmse_rms");
        cdsp_host_json_number(&j, stat_rms(&s_rmse));
        cdsp_host_json_key(&j, "rmse_max");
        cdsp_host_json_number(&j, s_rmse.n ? s_rmse.max : NAN);
        cdsp_host_json_key(&j, "angle_rms_deg");
        cdsp_host_json_number(&j, stat_rms(&s_angle));
        cdsp_host_json_key(&j, "angle_max_deg");
        cdsp_host_json_number(&j, s_angle.n ? s_angle.max : NAN);
        cdsp_host_json_key(&j, "d_error_mean");
        cdsp_host_json_number(&j, s_dist.n ? s_dist.sum / s_dist.n : NAN);
        cdsp_host_json_key(&j, "d_error_rms");
        cdsp_host_json_number(&j, stat_rms(&s_dist));
        cdsp_host_json_key(&j, "d_error_max");
        cdsp_host_json_number(&j, s_dist.n ? s_dist.max : NAN);
        cdsp_host_json_end_object(&j);
        cdsp_host_json_end_object(&j);
        if (cdsp_host_json_finish(&j))
            printf("%s\n", buf);
    } else {
        printf("summary: %zu frames, %d solved, %d failed", rs.n, s_rmse.n, failed);
        if (no_truth)
            printf(", %d without truth", no_truth);
        if (s_rmse.n)
            printf("; axis RMSE %.4f (RMS over frames), max %.4f; angle %.4f deg RMS, max %.4f; "
                   "distance error mean %+.4f, RMS %.4f, max %.4f\n",
                   stat_rms(&s_rmse), s_rmse.max, stat_rms(&s_angle), s_angle.max,
                   s_dist.sum / s_dist.n, stat_rms(&s_dist), s_dist.max);
        else
            printf("\n");
    }
    tool_records_free(&rs);
    tool_truth_free(&t);
    free(pos);
    if (fflush(stdout) != 0 || ferror(stdout))
        return tool_usage_error("compare", "writing the output failed");
    return failed || no_truth || over ? TOOL_EXIT_PARTIAL : TOOL_EXIT_OK;
}
