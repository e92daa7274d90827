/* src/attack/attack_internal.h: shared by the attack stage's files. Not installed. */
#ifndef VF_ATTACK_INTERNAL_H
#define VF_ATTACK_INTERNAL_H

#include "vf/attack_eval.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

/* v_star.png, samples.png (24 samples of p*(v), red = fooled), loss.png (not for random
 * search: st NULL) and fluctuation.png, written into dir. */
vf_status vf__attack_write_pictures(const char *dir, vf_view_loss *vl, const vf_attack_state *st,
                                    const vf_attack_eval *ev);

#endif
