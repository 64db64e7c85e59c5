/*
 * seccomp.c - what a submission may ask the kernel, as a seccomp BPF program.
 *
 * A tiny assembler (labels resolved when the program is complete) and the
 * policy written with it (install_filter): threads but no processes, files
 * read but never written, signals to itself only, W^X, the grader's own
 * mappings (texture windows, the code that reports faults) never changed,
 * limits never raised, and a trap for every syscall a lookup has no use for,
 * which faults.c reports by name. Linux only, like the worker.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <linux/sockios.h>
#include <sched.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "seccomp.h"

struct syscall_name { long nr; const char *name; };

/* Every syscall the filter refuses by trapping, with its name for the report. */
static const struct syscall_name forbidden_names[] = {
#define NAME(n) { __NR_##n, #n },
#ifdef __NR_fork
    NAME(fork) NAME(vfork) NAME(open) NAME(creat) NAME(unlink) NAME(rename)
    NAME(rmdir) NAME(mkdir) NAME(link) NAME(symlink) NAME(chmod) NAME(chown)
    NAME(lchown) NAME(mknod)
#endif
    NAME(clone) NAME(execve) NAME(execveat) NAME(socket) NAME(socketpair)
    NAME(connect) NAME(bind) NAME(listen) NAME(ptrace) NAME(kill) NAME(tkill)
    NAME(tgkill) NAME(openat) NAME(unlinkat) NAME(renameat) NAME(renameat2)
    NAME(mkdirat) NAME(linkat) NAME(symlinkat) NAME(fchmodat) NAME(fchownat)
    NAME(mknodat) NAME(truncate) NAME(mount) NAME(umount2) NAME(pivot_root)
    NAME(chroot) NAME(unshare) NAME(setns) NAME(process_vm_readv)
    NAME(process_vm_writev) NAME(io_uring_setup) NAME(bpf) NAME(perf_event_open)
    NAME(userfaultfd) NAME(keyctl) NAME(add_key) NAME(request_key) NAME(reboot)
    NAME(init_module) NAME(finit_module) NAME(delete_module) NAME(kexec_load)
    NAME(memfd_create) NAME(remap_file_pages) NAME(shmat) NAME(process_madvise)
    NAME(pidfd_open) NAME(pidfd_send_signal) NAME(pidfd_getfd) NAME(rt_sigqueueinfo)
    NAME(rt_tgsigqueueinfo) NAME(seccomp) NAME(kcmp) NAME(name_to_handle_at)
    NAME(open_by_handle_at) NAME(fanotify_init) NAME(prctl) NAME(fcntl) NAME(ioctl)
    /* System V and POSIX IPC outlive the worker and are shared between
     * workers outside bubblewrap (privilege-drop): none. */
    NAME(shmget) NAME(msgget) NAME(semget) NAME(mq_open)
    /* The machine's state: clock, log, accounting, swap, names, I/O ports
     * (most need privileges the worker lacks in a sandbox; all matter in
     * unsafe mode), and personality (READ_IMPLIES_EXEC would get round W^X). */
    NAME(settimeofday) NAME(clock_settime) NAME(clock_adjtime) NAME(adjtimex) NAME(syslog)
    NAME(acct) NAME(swapon) NAME(swapoff) NAME(sethostname) NAME(setdomainname) NAME(quotactl)
    NAME(vhangup) NAME(personality) NAME(sync) NAME(syncfs)
#ifdef __NR_iopl
    NAME(iopl) NAME(ioperm)
#endif
    /* Refused only on the grader's memory (protected ranges) or for W^X. */
    NAME(mprotect) NAME(pkey_mprotect) NAME(munmap) NAME(madvise) NAME(mmap) NAME(mremap)
#undef NAME
};

/* fcntl and ioctl commands that choose which process gets a signal (SIGIO,
 * or any signal with F_SETSIG): refused, so a worker can signal no one. */
static const struct syscall_name signal_commands[] = {
    { F_SETOWN, "F_SETOWN" }, { F_SETOWN_EX, "F_SETOWN_EX" }, { F_SETSIG, "F_SETSIG" },
    { F_NOTIFY, "F_NOTIFY" }, { F_SETLEASE, "F_SETLEASE" }, { F_SETFL, "F_SETFL with O_ASYNC" },
};
static const struct syscall_name signal_ioctls[] = {
    { FIOSETOWN, "FIOSETOWN" }, { SIOCSPGRP, "SIOCSPGRP" }, { TIOCSPGRP, "TIOCSPGRP" }, { FIOASYNC, "FIOASYNC" },
};

const char *command_name(long nr, unsigned command)
{
    const struct syscall_name *names = nr == __NR_fcntl ? signal_commands : signal_ioctls;
    size_t count = nr == __NR_fcntl ? sizeof signal_commands / sizeof signal_commands[0]
                                    : sizeof signal_ioctls / sizeof signal_ioctls[0];
    for (size_t i = 0; i < count; i++)
        if ((unsigned)names[i].nr == command)
            return names[i].name;
    return "(a command outside the allowed list)";
}

const char *trapped_syscall_name(long nr)
{
    const char *name = "unknown";
    for (size_t i = 0; i < sizeof forbidden_names / sizeof forbidden_names[0]; i++)
        if (forbidden_names[i].nr == nr)
            name = forbidden_names[i].name;
    return name;
}

/* ---- the seccomp filter -------------------------------------------------- */

#if defined(__x86_64__)
#define OUR_AUDIT_ARCH AUDIT_ARCH_X86_64
#elif defined(__aarch64__)
#define OUR_AUDIT_ARCH AUDIT_ARCH_AARCH64
#endif

#define MAX_FILTER 4000
static struct sock_filter program[MAX_FILTER];
static unsigned short program_length;

/* Forward jumps to labels, resolved once the program is complete. */
#define MAX_LABELS 4096
static int label_at[MAX_LABELS];
static int label_count;
static struct { unsigned short insn; short label; char field; } fixups[2 * MAX_LABELS];
static int fixup_count;
static int program_broken;

static void add_fixup(int at, int label, char field)
{
    if (fixup_count >= 2 * MAX_LABELS) {
        program_broken = 1;
        return;
    }
    fixups[fixup_count].insn = (unsigned short)at;
    fixups[fixup_count].label = (short)label;
    fixups[fixup_count++].field = field;
}

static int new_label(void)
{
    if (label_count >= MAX_LABELS) {
        program_broken = 1;
        return 0;
    }
    label_at[label_count] = -1;
    return label_count++;
}

static void place(int label)
{
    label_at[label] = program_length;
}

static void emit(struct sock_filter f)
{
    if (program_length < MAX_FILTER)
        program[program_length++] = f;
}

static void jump(unsigned value, unsigned char if_true, unsigned char if_false)
{
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, value, if_true, if_false));
}

static void load(unsigned offset)
{
    emit((struct sock_filter)BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offset));
}

static void ret(unsigned action)
{
    emit((struct sock_filter)BPF_STMT(BPF_RET | BPF_K, action));
}

#define ARG_LOW(i) ((unsigned)offsetof(struct seccomp_data, args[i]))
#define ARG_HIGH(i) ((unsigned)offsetof(struct seccomp_data, args[i]) + 4)
#define TRAP SECCOMP_RET_TRAP
#define ALLOW SECCOMP_RET_ALLOW
#define FAIL(e) (SECCOMP_RET_ERRNO | ((e) & SECCOMP_RET_DATA))

/* Each rule below starts with the syscall number in the accumulator and
 * either returns or leaves it there untouched. */

/* syscall == nr -> action */
static void on_call(long nr, unsigned action)
{
    jump((unsigned)nr, 0, 1);
    ret(action);
}

/* syscall == nr -> (args[arg] & mask) ? if_set : if_clear */
static void on_flags(long nr, int arg, unsigned mask, unsigned if_set, unsigned if_clear)
{
    jump((unsigned)nr, 0, 4);
    load(ARG_LOW(arg));
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JSET | BPF_K, mask, 0, 1));
    ret(if_set);
    ret(if_clear);
}

/* syscall == nr -> (args[arg] == value) ? if_equal : otherwise */
static void on_arg(long nr, int arg, unsigned value, unsigned if_equal, unsigned otherwise)
{
    jump((unsigned)nr, 0, 6);
    load(ARG_HIGH(arg));
    jump(0, 0, 3);
    load(ARG_LOW(arg));
    jump(value, 0, 1);
    ret(if_equal);
    ret(otherwise);
}

/* syscall == nr -> (args[0] in values) ? action : allow */
static void on_arg_in_set(long nr, const int *values, unsigned count, unsigned action)
{
    jump((unsigned)nr, 0, (unsigned char)(count + 3));
    load(ARG_LOW(0));
    for (unsigned i = 0; i < count; i++)
        jump((unsigned)values[i], (unsigned char)(count - i), 0);
    ret(ALLOW);
    ret(action);
}

/* syscall == nr -> (args[arg] != NULL) ? action : allow */
static void on_nonnull(long nr, int arg, unsigned action)
{
    jump((unsigned)nr, 0, 6);
    load(ARG_LOW(arg));
    jump(0, 0, 3);
    load(ARG_HIGH(arg));
    jump(0, 0, 1);
    ret(ALLOW);
    ret(action);
}

/* syscall == nr -> args[arg] is 0 (the caller) or `self` ? allow : action.
 * Scheduling another process: in privilege-drop mode every worker is uid
 * nobody in one pid namespace, so a submission could put another student's
 * worker, or the speed check's reference, into SCHED_IDLE to starve it. */
static void on_other_pid(long nr, int arg, unsigned self, unsigned action)
{
    jump((unsigned)nr, 0, 7);
    load(ARG_HIGH(arg));
    jump(0, 0, 3);
    load(ARG_LOW(arg));
    jump(0, 2, 0);
    jump(self, 1, 0);
    ret(action);
    ret(ALLOW);
}

/* Conditional jump on A against k (code: BPF_JEQ, BPF_JGT, BPF_JGE, BPF_JSET)
 * to labels; -1 means the next instruction. */
static void jump_to(unsigned code, unsigned k, int if_true, int if_false)
{
    int at = program_length;
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | code | BPF_K, k, 0, 0));
    if (if_true >= 0)
        add_fixup(at, if_true, 't');
    if (if_false >= 0)
        add_fixup(at, if_false, 'f');
}

static void always_to(int label)
{
    int at = program_length;
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JA, 0, 0, 0));
    add_fixup(at, label, 'k');
}

static int resolve_labels(void)
{
    for (int i = 0; i < fixup_count; i++) {
        int target = label_at[fixups[i].label], at = fixups[i].insn;
        if (target < 0 || target <= at)
            return -1;
        unsigned offset = (unsigned)(target - at - 1);
        if (fixups[i].field == 'k')
            program[at].k = offset;
        else if (offset > 255)
            return -1;
        else if (fixups[i].field == 't')
            program[at].jt = (unsigned char)offset;
        else
            program[at].jf = (unsigned char)offset;
    }
    return 0;
}

static void stmt(unsigned code, unsigned k)
{
    emit((struct sock_filter)BPF_STMT(code, k));
}

/* Memory the submission must not remap, unmap or reprotect: the texture
 * windows and every file mapping present before it is loaded (the worker,
 * ld.so, libc, the C++ runtime: their code, relocations and data), so it can
 * neither switch a guard off nor patch the code that reports a fault. */
#define MAX_RANGES 40
static struct { uint64_t first, end; } protected_ranges[MAX_RANGES];
static int range_count;

void protect(uint64_t first, uint64_t end)
{
    if (range_count > 0 && protected_ranges[range_count - 1].end == first) {
        protected_ranges[range_count - 1].end = end;   /* adjacent: one range */
        return;
    }
    if (range_count < MAX_RANGES) {
        protected_ranges[range_count].first = first;
        protected_ranges[range_count++].end = end;
        return;
    }
    /* Too many: widen the last one (protects a gap too, which is only stricter). */
    protected_ranges[range_count - 1].end = end;
}

/* Every mapping backed by a file or the kernel ([vdso], [vvar]): code,
 * relocations (read-only after RELRO) and data of the worker, ld.so, libc
 * and the C++ runtime. Anonymous memory is left alone (malloc unmaps and
 * trims it). Read from /proc/self/maps before the filter and any chroot. */
int collect_protected_ranges(void)
{
    FILE *maps = fopen("/proc/self/maps", "re");
    if (!maps)
        return -1;
    char line[4096];
    while (fgets(line, sizeof line, maps)) {
        unsigned long long first, end, offset, inode;
        char perms[8], dev[32];
        int name_at = 0;
        if (sscanf(line, "%llx-%llx %7s %llx %31s %llu %n", &first, &end, perms, &offset, dev, &inode,
                   &name_at) < 6 || name_at <= 0)
            continue;
        const char *name = line + name_at;
        if (name[0] == '/' || !strncmp(name, "[vdso]", 6) || !strncmp(name, "[vvar", 5))
            protect(first, end);
    }
    fclose(maps);
    return 0;
}

/* Trap when [args[a], args[a] + args[len]) overlaps a protected range; when
 * flag_mask is not 0, only if args[flag_arg] & flag_mask. Otherwise falls
 * through with the syscall number in A again. Uses scratch M[0] (end, low
 * word) and M[1] (end, high word). */
static void on_protected_overlap(long nr, int a, int len, int flag_arg, unsigned flag_mask)
{
    int skip = new_label(), in_block = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    if (flag_mask) {
        load(ARG_LOW(flag_arg));
        jump_to(BPF_JSET, flag_mask, -1, skip);
    }
    /* end = a + len, 64 bits from two 32-bit halves with the carry. */
    load(ARG_LOW(len));
    stmt(BPF_MISC | BPF_TAX, 0);
    load(ARG_LOW(a));
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_ST, 0);
    int no_carry = new_label(), carried = new_label();
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JGE | BPF_X, 0, 0, 0));   /* sum >= len: no carry */
    add_fixup(program_length - 1, no_carry, 't');
    stmt(BPF_LD | BPF_IMM, 1);
    always_to(carried);
    place(no_carry);
    stmt(BPF_LD | BPF_IMM, 0);
    place(carried);
    stmt(BPF_ST, 1);
    load(ARG_HIGH(len));
    stmt(BPF_MISC | BPF_TAX, 0);
    load(ARG_HIGH(a));
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_MISC | BPF_TAX, 0);
    stmt(BPF_LD | BPF_MEM, 1);
    stmt(BPF_ALU | BPF_ADD | BPF_X, 0);
    stmt(BPF_ST, 1);
    for (int i = 0; i < range_count; i++) {
        uint64_t first = protected_ranges[i].first, end = protected_ranges[i].end;
        unsigned first_hi = (unsigned)(first >> 32), first_lo = (unsigned)first;
        unsigned end_hi = (unsigned)(end >> 32), end_lo = (unsigned)end;
        int next = new_label(), check_start = new_label(), low_end = new_label(), low_start = new_label(),
            trap = new_label();
        /* call end > first? */
        stmt(BPF_LD | BPF_MEM, 1);
        jump_to(BPF_JGT, first_hi, check_start, -1);
        jump_to(BPF_JEQ, first_hi, low_end, next);
        place(low_end);
        stmt(BPF_LD | BPF_MEM, 0);
        jump_to(BPF_JGT, first_lo, check_start, next);
        /* call start < end? */
        place(check_start);
        load(ARG_HIGH(a));
        jump_to(BPF_JGT, end_hi, next, -1);
        jump_to(BPF_JEQ, end_hi, low_start, trap);
        place(low_start);
        load(ARG_LOW(a));
        jump_to(BPF_JGE, end_lo, next, trap);
        place(trap);
        ret(TRAP);
        place(next);
    }
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

/* Trap when args[arg] & mask (and, with mask2 not 0, args[arg2] & mask2);
 * otherwise fall through with the syscall number in A again. */
static void trap_on_bits(long nr, int arg, unsigned mask, int arg2, unsigned mask2)
{
    int skip = new_label(), in_block = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    load(ARG_LOW(arg));
    if (mask2) {
        int second = new_label();
        jump_to(BPF_JSET, mask, second, skip);
        place(second);
        load(ARG_LOW(arg2));
        jump_to(BPF_JSET, mask2, -1, skip);
    } else {
        jump_to(BPF_JSET, mask, -1, skip);
    }
    ret(TRAP);
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

/* fcntl: only the commands a lookup's runtime may use (descriptor flags,
 * duplicates, locks, pipe size, seals); F_SETFL only without O_ASYNC.
 * Everything else traps: F_SETOWN(_EX), F_SETSIG, F_NOTIFY, F_SETLEASE and
 * O_ASYNC would have the kernel deliver a signal of the caller's choosing
 * to a pid of its choosing (a classmate's worker, the speed check's
 * reference), which kill's rule never sees. */
static const unsigned fcntl_allowed[] = {
    F_DUPFD, F_GETFD, F_SETFD, F_GETFL, F_GETLK, F_SETLK, F_SETLKW, F_OFD_GETLK, F_OFD_SETLK,
    F_OFD_SETLKW, F_DUPFD_CLOEXEC, F_GETPIPE_SZ, F_GET_SEALS,
};
/* ioctl: isatty (TCGETS), the terminal size, FIONREAD, FIONBIO and the
 * close-on-exec pair are allowed; the ones that set a signal's owner trap;
 * any other answers ENOTTY (what a pipe says to a terminal request). */
static const unsigned ioctl_allowed[] = { TCGETS, TIOCGWINSZ, FIONREAD, FIONBIO, FIOCLEX, FIONCLEX };

static void on_command(long nr, const unsigned *allowed, size_t count, const struct syscall_name *trapped,
                       size_t trapped_count, unsigned otherwise, unsigned async_command)
{
    int skip = new_label(), in_block = new_label(), allow = new_label(), trap = new_label(), async = new_label();
    jump_to(BPF_JEQ, (unsigned)nr, in_block, -1);
    always_to(skip);
    place(in_block);
    load(ARG_LOW(1));      /* the command: an unsigned int, the kernel ignores the high word */
    if (async_command)
        jump_to(BPF_JEQ, async_command, async, -1);
    for (size_t i = 0; i < count; i++)
        jump_to(BPF_JEQ, allowed[i], allow, -1);
    for (size_t i = 0; i < trapped_count; i++)
        jump_to(BPF_JEQ, (unsigned)trapped[i].nr, trap, -1);
    ret(otherwise);
    place(async);
    if (async_command) {
        load(ARG_LOW(2));
        jump_to(BPF_JSET, O_ASYNC, trap, allow);
    }
    place(allow);
    ret(ALLOW);
    place(trap);
    ret(TRAP);
    place(skip);
    load((unsigned)offsetof(struct seccomp_data, nr));
}

static const int guarded_signals[] = { SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGSYS, SIGXCPU };

int install_filter(void)
{
    unsigned pid = (unsigned)getpid();
    const unsigned write_flags = O_WRONLY | O_RDWR | O_CREAT | O_TRUNC | O_APPEND;
    load((unsigned)offsetof(struct seccomp_data, arch));
    jump(OUR_AUDIT_ARCH, 1, 0);
    ret(TRAP);
    load((unsigned)offsetof(struct seccomp_data, nr));
#if defined(__x86_64__)
    emit((struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JGE | BPF_K, __X32_SYSCALL_BIT, 0, 1));
    ret(TRAP);
#endif
    /* Threads are allowed (clone with CLONE_THREAD); new processes are not.
     * clone3 hides its flags in memory, so it answers "not supported" and
     * glibc falls back to clone. */
    on_flags(__NR_clone, 0, CLONE_THREAD, ALLOW, TRAP);
    on_call(__NR_clone3, FAIL(ENOSYS));
    on_call(__NR_openat2, FAIL(ENOSYS));
    /* Opening for reading stays allowed (dlopen needs it); writing traps. */
    on_flags(__NR_openat, 2, write_flags, TRAP, ALLOW);
#ifdef __NR_open
    on_flags(__NR_open, 1, write_flags, TRAP, ALLOW);
#endif
    /* Signals only to ourselves (raise, abort). */
    on_arg(__NR_kill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_tgkill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_tkill, 0, pid, ALLOW, TRAP);
    on_arg(__NR_rt_sigqueueinfo, 0, pid, ALLOW, TRAP);
    on_arg(__NR_rt_tgsigqueueinfo, 0, pid, ALLOW, TRAP);
    on_arg(__NR_prctl, 0, PR_SET_SECCOMP, TRAP, ALLOW);
    /* W^X: no memory becomes executable after loading except the
     * submission's own file mappings (dlopen maps them from the file). */
    trap_on_bits(__NR_mprotect, 2, PROT_EXEC, 0, 0);
    trap_on_bits(__NR_pkey_mprotect, 2, PROT_EXEC, 0, 0);
    trap_on_bits(__NR_mmap, 2, PROT_EXEC, 2, PROT_WRITE);
    trap_on_bits(__NR_mmap, 2, PROT_EXEC, 3, MAP_ANONYMOUS);
    /* The grader's memory (texture windows, the code that reports faults)
     * keeps its mappings and protections. */
    on_protected_overlap(__NR_mprotect, 0, 1, 0, 0);
    on_protected_overlap(__NR_pkey_mprotect, 0, 1, 0, 0);
    on_protected_overlap(__NR_munmap, 0, 1, 0, 0);
    on_protected_overlap(__NR_madvise, 0, 1, 0, 0);
    on_protected_overlap(__NR_mmap, 0, 1, 3, MAP_FIXED);
    on_protected_overlap(__NR_mremap, 0, 1, 0, 0);
    on_protected_overlap(__NR_mremap, 4, 2, 3, MREMAP_FIXED);
    /* Our crash handlers stay ours, and limits cannot be raised. */
    on_arg_in_set(__NR_rt_sigaction, guarded_signals,
                  sizeof guarded_signals / sizeof guarded_signals[0], FAIL(EPERM));
    on_call(__NR_setrlimit, FAIL(EPERM));
    on_nonnull(__NR_prlimit64, 2, FAIL(EPERM));
    /* Scheduling, priority and memory placement of itself only (another
     * worker of uid nobody could be starved: see on_other_pid). */
    on_other_pid(__NR_sched_setscheduler, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setparam, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setattr, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_sched_setaffinity, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_migrate_pages, 0, pid, FAIL(EPERM));
    on_other_pid(__NR_move_pages, 0, pid, FAIL(EPERM));
    on_call(__NR_setpriority, FAIL(EPERM));     /* PRIO_USER reaches every process of the uid */
    on_call(__NR_ioprio_set, FAIL(EPERM));
    /* Signals by way of a descriptor's owner (see fcntl_allowed). */
    on_command(__NR_fcntl, fcntl_allowed, sizeof fcntl_allowed / sizeof fcntl_allowed[0], signal_commands,
               sizeof signal_commands / sizeof signal_commands[0] - 1, TRAP, F_SETFL);
    on_command(__NR_ioctl, ioctl_allowed, sizeof ioctl_allowed / sizeof ioctl_allowed[0], signal_ioctls,
               sizeof signal_ioctls / sizeof signal_ioctls[0], FAIL(ENOTTY), 0);
    for (size_t i = 0; i < sizeof forbidden_names / sizeof forbidden_names[0]; i++) {
        long nr = forbidden_names[i].nr;
        int handled = nr == __NR_clone || nr == __NR_openat || nr == __NR_kill ||
                      nr == __NR_tgkill || nr == __NR_tkill || nr == __NR_rt_sigqueueinfo ||
                      nr == __NR_rt_tgsigqueueinfo || nr == __NR_mprotect || nr == __NR_pkey_mprotect ||
                      nr == __NR_munmap || nr == __NR_madvise || nr == __NR_mmap || nr == __NR_mremap ||
                      nr == __NR_prctl || nr == __NR_fcntl || nr == __NR_ioctl;
#ifdef __NR_open
        handled = handled || nr == __NR_open;
#endif
        if (!handled)
            on_call(nr, TRAP);
    }
    ret(ALLOW);
    if (program_length >= MAX_FILTER || program_broken || resolve_labels() != 0)
        return -1;
    struct sock_fprog fprog = { program_length, program };
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
        return -1;
    return prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &fprog);
}
