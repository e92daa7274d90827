/* vfcapture: the command line. Dispatches `vfcapture <command> [options]` to one file per
 * command in pipeline/. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

static const cli_command commands[] = {
    {"run", cmd_run, "the whole pipeline on one capture: ingest, poses, train, attack, export"},
    {"ingest", cmd_ingest, "bring a capture into a workspace (video, photos, webcam, posed set, 3D model)"},
    {"poses", cmd_poses, "camera poses by structure from motion (COLMAP), in the object frame"},
    {"train", cmd_train, "fit a radiance field to the posed images (CPU, minutes)"},
    {"render", cmd_render, "render the trained field from a viewpoint or camera pose"},
    {"eval", cmd_eval, "PSNR/SSIM of the trained field on a posed test set"},
    {"attack", cmd_attack, "ViewFool: adversarial viewpoint distribution on the trained field"},
    {"real", cmd_real, "check the attack's viewpoints on the 3D model itself (Real(v*))"},
    {"transfer", cmd_transfer, "success rate of an attack's sampled viewpoints on other models"},
    {"export", cmd_export, "target shots for the attack's viewpoints: poses, words, previews, card"},
    {"localize", cmd_localize, "where was this frame taken? poses of new photos or video frames"},
    {"reshoot", cmd_reshoot, "guided capture at a target: live advice, saves frames on target"},
    {"score", cmd_score, "physical attack success rate from a re-captured video"},
    {"simulate", cmd_simulate, "a simulated studio: film a 3D model as a phone would, re-shoot targets"},
    {"classify", cmd_classify, "classify images with an ImageNet model, print top-5"},
    {"models", cmd_models, "list the classifiers found by name, with input size and engine"},
    {"benchmark", cmd_benchmark, "ImageNet-V style set from attacked objects; score classifiers"},
    {"study", cmd_study, "many objects x classifiers x settings through Snakemake (or Slurm)"},
    {"tables", cmd_tables, "the paper's tables of a study's finished workspaces"},
    {"info", cmd_info, "show a workspace's stages, parameters and outputs"},
    {"calib", cmd_calib, "camera calibration (checkerboard) and a workspace's metric scale"},
};
static const int command_count = sizeof commands / sizeof commands[0];

static void print_usage(FILE *out)
{
    fprintf(out,
            "vfcapture %s: viewpoint attacks on image classifiers, from a capture of a real object\n"
            "\n"
            "usage: vfcapture <command> [options]   (vfcapture <command> --help for details)\n"
            "\n"
            "commands:\n",
            VF_VERSION);
    for (int i = 0; i < command_count; i++)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\n"
                 "Exit codes: 0 ok, 1 bad input (the message says what to fix), 2 internal failure.\n"
                 "Models and data are found under $VF_SHARED_DIR (default: %s).\n",
            VF_DEFAULT_SHARED_DIR);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        print_usage(stderr);
        return 1;
    }
    const char *name = argv[1];
    if (!strcmp(name, "-h") || !strcmp(name, "--help") || !strcmp(name, "help")) {
        print_usage(stdout);
        return 0;
    }
    if (!strcmp(name, "--version")) {
        printf("vfcapture %s\n", VF_VERSION);
        return 0;
    }
    for (int i = 0; i < command_count; i++)
        if (!strcmp(name, commands[i].name))
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "vfcapture: unknown command '%s' (see 'vfcapture --help')\n", name);
    return 1;
}
