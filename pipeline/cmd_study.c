/* vfcapture study: run a study's workflow (workflow/Snakefile) with Snakemake, on this
 * machine or through Slurm. The command only assembles the snakemake line, prints it and
 * hands over; everything else is the workflow's (and, in the end, `vfcapture tables`). */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "vf/process.h"

static const char usage[] =
    "usage: vfcapture study STUDY.yaml [--cores N | --slurm] [--dry-run] [-- SNAKEMAKE ARGS]\n"
    "\n"
    "Run a study: many objects x classifiers x attack settings, the paper's tables at the end\n"
    "(STUDY's 'out' folder: one workspace an object, tables/ from 'vfcapture tables'). The\n"
    "study file lists the objects (any input 'vfcapture ingest' takes, with their labels),\n"
    "the classifiers, the attack settings and the columns wanted; samples/study_tiny.yaml\n"
    "describes every key. The work is the shipped Snakemake workflow (one job per stage per\n"
    "object, per classifier and setting for attack, real and transfer); this command prints\n"
    "the snakemake line it runs, which can be run as it is. Finished stages are not redone:\n"
    "run it again after a failure or an interruption to continue.\n"
    "\n"
    "options:\n"
    "      --cores N          run on this machine with N cores (default: all)\n"
    "      --slurm            submit each job to Slurm (the profile in workflow/slurm/)\n"
    "      --dry-run          print the jobs that would run, run none\n"
    "      --workflow DIR     the workflow folder (default $VF_WORKFLOW_DIR, else " VF_WORKFLOW_DIR
    ")\n" CLI_COMMON_HELP;

enum { OPT_CORES = CLI_OPT_FIRST_CUSTOM, OPT_SLURM, OPT_WORKFLOW, OPT_DRY_RUN };

int cmd_study(int argc, char **argv)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        {"cores", required_argument, NULL, OPT_CORES},
        {"slurm", no_argument, NULL, OPT_SLURM},
        {"dry-run", no_argument, NULL, OPT_DRY_RUN},
        {"workflow", required_argument, NULL, OPT_WORKFLOW},
        {0, 0, 0, 0},
    };
    cli_flags flags = {0};
    const char *cores = NULL, *workflow = getenv("VF_WORKFLOW_DIR");
    int slurm = 0, dry = 0, c;
    long n;
    vf_status s = VF_OK;
    const int total = argc;
    int extra = argc; /* snakemake's own options: what follows "--" */
    for (int i = 1; i < total; i++)
        if (!strcmp(argv[i], "--")) {
            extra = i + 1, argc = i;
            break;
        }
    while (s == VF_OK && (c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &flags, "study", usage))
            continue;
        if (c == OPT_CORES && (s = cli_count("--cores", optarg, 1, 4096, &n)) == VF_OK)
            cores = optarg;
        else if (c == OPT_SLURM)
            slurm = 1;
        else if (c == OPT_DRY_RUN)
            dry = 1;
        else if (c == OPT_WORKFLOW)
            workflow = optarg;
    }
    if (s == VF_OK && optind >= argc)
        s = vf_fail(VF_EINPUT, "give the study file (see 'vfcapture study --help')");
    if (s == VF_OK && slurm && cores)
        s = vf_fail(VF_EINPUT, "--cores and --slurm: choose one (Slurm gives each job its cores)");
    const char *config = s == VF_OK ? argv[optind++] : NULL;
    if (s == VF_OK && !vf_is_file(config))
        s = vf_fail(VF_EINPUT, "%s: no such study file", config);
    if (s == VF_OK && optind < argc)
        s = vf_fail(VF_EINPUT, "give one study file; snakemake's own options go after '--'");
    char snakemake[VF_PATH_MAX], snakefile[VF_PATH_MAX], profile[VF_PATH_MAX], self[VF_PATH_MAX];
    if (s == VF_OK)
        s = vf_find_program("VF_SNAKEMAKE", "snakemake",
                            "apt-get install snakemake (scripts/setup.sh does)", snakemake,
                            sizeof snakemake);
    if (!workflow || !workflow[0])
        workflow = VF_WORKFLOW_DIR;
    if (s == VF_OK)
        s = vf_path_join(snakefile, sizeof snakefile, workflow, "Snakefile");
    if (s == VF_OK)
        s = vf_path_join(profile, sizeof profile, workflow, "slurm");
    if (s == VF_OK && !vf_is_file(snakefile))
        s = vf_fail(VF_EINPUT, "no workflow at %s: give --workflow DIR", snakefile);
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    self[len > 0 ? len : 0] = '\0';
    if (!getenv("VF_TOOL")) /* the workflow's jobs call this very vfcapture */
        setenv("VF_TOOL", self, 1);
    if (s != VF_OK)
        return cli_fail("study", s);

    /* VF_TOOL=SELF snakemake -s SNAKEFILE --configfile STUDY (--cores N | --profile SLURM)
     * --keep-going [-n] [--quiet] [ARGS...] */
    char *args[64];
    int k = 0;
    const char *fixed[] = {snakemake, "-s", snakefile, "--configfile", config};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        args[k++] = (char *)fixed[i];
    if (slurm)
        args[k++] = "--profile", args[k++] = profile;
    else
        args[k++] = "--cores", args[k++] = (char *)(cores ? cores : "all");
    args[k++] = "--keep-going";
    if (dry)
        args[k++] = "--dry-run";
    if (flags.quiet)
        args[k++] = "--quiet";
    for (int i = extra; i < total && k < 63; i++)
        args[k++] = argv[i];
    args[k] = NULL;
    fprintf(stderr, "running: VF_TOOL=%s", getenv("VF_TOOL"));
    for (int i = 0; i < k; i++)
        fprintf(stderr, " %s", args[i]);
    fputc('\n', stderr);
    if (slurm && !getenv("USER"))
        setenv("USER", "root", 0); /* Snakemake 7.21's --slurm reads $USER (unset under CI) */
    execv(snakemake, args);
    vf_fail(VF_EINTERNAL, "cannot start %s", snakemake);
    return cli_fail("study", VF_EINTERNAL);
}
