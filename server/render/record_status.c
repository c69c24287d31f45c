/* record_status.c — a recording job's newest `recording` text in its slot
 * (sl_render.h): posted by the sessions when a job is queued and by the render
 * thread as it runs. Lock held; any thread.
 */
#include "sl_render.h"

#include <stdlib.h>

void sl_record_status_locked(sl_render_slot *s, const sl_record_job *j, const char *state, cJSON *extra)
{
    cJSON *m = extra ? extra : cJSON_CreateObject();
    if (!m)
        return;
    cJSON_AddStringToObject(m, "type", "recording");
    cJSON_AddNumberToObject(m, "id", j->id);
    cJSON_AddStringToObject(m, "state", state);
    cJSON_AddNumberToObject(m, "frames", j->frames);
    char *text = cJSON_PrintUnformatted(m);
    cJSON_Delete(m);
    if (!text)
        return;
    free(s->record_text);
    s->record_text = text;
    s->record_seq++;
}
