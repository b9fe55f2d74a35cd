/* The same through the C API (edgefem::capi). */
#include <stdio.h>

#include "edgefem/edgefem.h"

int main(void) {
    edgefem_scene* scene = NULL;
    edgefem_sim* sim = NULL;
    if (edgefem_scene_create_box(10, 5, 4, 0.01, &scene) != EDGEFEM_OK ||
        edgefem_scene_set_gravity(scene, 0, 0, -9.81) != EDGEFEM_OK ||
        edgefem_sim_create(scene, &sim) != EDGEFEM_OK || edgefem_sim_step(sim, NULL) != EDGEFEM_OK) {
        fprintf(stderr, "edgefem_consumer_c: %s\n", edgefem_last_error());
        return 1;
    }
    printf("edgefem_consumer_c: ok (edgefem %s)\n", edgefem_version_string());
    edgefem_sim_destroy(sim);
    edgefem_scene_destroy(scene);
    return 0;
}
