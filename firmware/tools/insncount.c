/* insncount: exact guest instruction counts under QEMU 7.2 (TCG plugin API v1), with
 * per-stage attribution. Derived from ../../../shared/tools/qemu-insncount (see README.md
 * beside this file); the declarations are hand-written to match QEMU 7.2's
 * include/qemu/qemu-plugin.h, because Debian's qemu-system-arm ships no plugin header.
 *
 * Arguments (-plugin ./libinsncount.so,ARG,ARG...):
 *   lo=ADDR,hi=ADDR  also count instructions with lo <= pc < hi (as the original tool)
 *   map=FILE         attribute every instruction to a stage. FILE has lines
 *                    "LO HI NAME" (hex addresses, [LO, HI)); NAME "inherit" charges the
 *                    instruction to the stage that ran last (shared helpers such as
 *                    libm's atan2f or memcpy count for the stage that called them);
 *                    addresses in no range count as "other".
 * Output (to -D FILE with -d plugin): "insns_total=N insns_in_range=M", then with map= one
 * line "stage NAME N" per stage.
 *
 * Build: gcc -O2 -shared -fPIC -fvisibility=hidden -o libinsncount.so insncount.c
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdbool.h>
typedef uint64_t qemu_plugin_id_t;
struct qemu_plugin_tb; struct qemu_plugin_insn; typedef struct qemu_info_t qemu_info_t;
enum qemu_plugin_op { QEMU_PLUGIN_INLINE_ADD_U64 };
enum qemu_plugin_cb_flags { QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_CB_R_REGS, QEMU_PLUGIN_CB_RW_REGS };
typedef void (*qemu_plugin_vcpu_tb_trans_cb_t)(qemu_plugin_id_t, struct qemu_plugin_tb *);
typedef void (*qemu_plugin_udata_cb_t)(qemu_plugin_id_t, void *);
typedef void (*qemu_plugin_vcpu_udata_cb_t)(unsigned int vcpu_index, void *userdata);
extern void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t, qemu_plugin_vcpu_tb_trans_cb_t);
extern size_t qemu_plugin_tb_n_insns(const struct qemu_plugin_tb *);
extern struct qemu_plugin_insn *qemu_plugin_tb_get_insn(const struct qemu_plugin_tb *, size_t);
extern uint64_t qemu_plugin_insn_vaddr(const struct qemu_plugin_insn *);
extern void qemu_plugin_register_vcpu_insn_exec_inline(struct qemu_plugin_insn *, enum qemu_plugin_op, void *, uint64_t);
extern void qemu_plugin_register_vcpu_insn_exec_cb(struct qemu_plugin_insn *, qemu_plugin_vcpu_udata_cb_t, enum qemu_plugin_cb_flags, void *);
extern void qemu_plugin_register_atexit_cb(qemu_plugin_id_t, qemu_plugin_udata_cb_t, void *);
extern void qemu_plugin_outs(const char *);
__attribute__((visibility("default"))) int qemu_plugin_version = 1;

static uint64_t total;          /* all executed guest instructions */
static uint64_t region;         /* instructions executed with lo <= pc < hi */
static uint64_t lo = 0, hi = 0; /* optional address range filter */

/* Stage attribution (map=FILE). Stage 0 is "other". */
#define MAX_STAGES 32
#define INHERIT (-1)
struct range { uint64_t lo, hi; int stage; };
static struct range *ranges;
static size_t n_ranges;
static char stage_names[MAX_STAGES][64] = { "other" };
static int n_stages = 1;
static uint64_t stage_count[MAX_STAGES];
static int current_stage;       /* the stage that ran last, for "inherit" instructions */

static int stage_id(const char *name) {
    if (!strcmp(name, "inherit")) return INHERIT;
    for (int i = 0; i < n_stages; i++)
        if (!strcmp(stage_names[i], name)) return i;
    if (n_stages == MAX_STAGES) { fprintf(stderr, "insncount: more than %d stages\n", MAX_STAGES); exit(2); }
    snprintf(stage_names[n_stages], sizeof stage_names[0], "%s", name);
    return n_stages++;
}

static int cmp_range(const void *a, const void *b) {
    const struct range *x = a, *y = b;
    return x->lo < y->lo ? -1 : x->lo > y->lo;
}

static void load_map(const char *path) {
    FILE *f = fopen(path, "r");
    if (!f) { fprintf(stderr, "insncount: cannot open map %s\n", path); exit(2); }
    size_t cap = 1024;
    ranges = malloc(cap * sizeof *ranges);
    char name[64];
    unsigned long long a, b;
    while (fscanf(f, "%llx %llx %63s", &a, &b, name) == 3) {
        if (n_ranges == cap) ranges = realloc(ranges, (cap *= 2) * sizeof *ranges);
        ranges[n_ranges++] = (struct range){ a, b, stage_id(name) };
    }
    fclose(f);
    qsort(ranges, n_ranges, sizeof *ranges, cmp_range);
}

static int stage_of(uint64_t pc) {
    size_t l = 0, h = n_ranges;
    while (l < h) {
        size_t m = (l + h) / 2;
        if (pc < ranges[m].lo) h = m;
        else if (pc >= ranges[m].hi) l = m + 1;
        else return ranges[m].stage;
    }
    return 0;
}

/* An instruction of a named stage that is the last of its stage in its translation block:
 * remember the stage for the helpers it may call next. */
static void set_stage(unsigned int vcpu, void *udata) {
    (void)vcpu;
    current_stage = (int)(intptr_t)udata;
}
/* An "inherit" instruction: charge the stage that ran last. */
static void charge_current(unsigned int vcpu, void *udata) {
    (void)vcpu; (void)udata;
    stage_count[current_stage]++;
}

static void tb_trans(qemu_plugin_id_t id, struct qemu_plugin_tb *tb) {
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &total, 1);
        uint64_t pc = qemu_plugin_insn_vaddr(insn);
        if (hi && pc >= lo && pc < hi)
            qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &region, 1);
        if (!ranges) continue;
        int s = stage_of(pc);
        if (s == INHERIT) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, charge_current, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else {
            qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &stage_count[s], 1);
            int next = INHERIT - 1; /* no next instruction in this block */
            if (i + 1 < n) next = stage_of(qemu_plugin_insn_vaddr(qemu_plugin_tb_get_insn(tb, i + 1)));
            if (next != s)
                qemu_plugin_register_vcpu_insn_exec_cb(insn, set_stage, QEMU_PLUGIN_CB_NO_REGS, (void *)(intptr_t)s);
        }
    }
}

static void at_exit(qemu_plugin_id_t id, void *p) {
    (void)id; (void)p;
    char buf[160];
    snprintf(buf, sizeof buf, "insns_total=%llu insns_in_range=%llu\n",
             (unsigned long long)total, (unsigned long long)region);
    qemu_plugin_outs(buf);
    if (ranges)
        for (int i = 0; i < n_stages; i++) {
            snprintf(buf, sizeof buf, "stage %s %llu\n", stage_names[i],
                     (unsigned long long)stage_count[i]);
            qemu_plugin_outs(buf);
        }
}

__attribute__((visibility("default")))
int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv) {
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (!strncmp(argv[i], "lo=", 3)) lo = strtoull(argv[i] + 3, NULL, 0);
        if (!strncmp(argv[i], "hi=", 3)) hi = strtoull(argv[i] + 3, NULL, 0);
        if (!strncmp(argv[i], "map=", 4)) load_map(argv[i] + 4);
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, tb_trans);
    qemu_plugin_register_atexit_cb(id, at_exit, NULL);
    return 0;
}
