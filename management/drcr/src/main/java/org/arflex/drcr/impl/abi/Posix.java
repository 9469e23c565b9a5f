package org.arflex.drcr.impl.abi;

import com.sun.jna.LastErrorException;
import com.sun.jna.Library;
import com.sun.jna.Native;
import com.sun.jna.Pointer;
import com.sun.jna.Structure;

/**
 * The libc calls the manager needs, through JNA. On glibc 2.34+ shm_open and mq_* live in libc
 * itself (load "c", not "rt"). Every call that sets errno is declared to throw
 * {@link LastErrorException}, so errors carry their errno.
 */
public interface Posix extends Library {

    /** The loaded libc. */
    Posix LIBC = Native.load("c", Posix.class);

    int O_RDONLY = 0;
    int O_WRONLY = 1;
    int O_RDWR = 2;
    int O_CREAT = 0100;
    int O_EXCL = 0200;
    int O_NONBLOCK = 04000;
    int PROT_READ = 1;
    int PROT_WRITE = 2;
    int MAP_SHARED = 1;
    int CLOCK_MONOTONIC = 1;
    int SIGKILL = 9;
    int SIGTERM = 15;
    int EEXIST = 17;
    int ENOENT = 2;
    int ETIMEDOUT = 110;
    int EAGAIN = 11;
    int ESRCH = 3;
    Pointer MAP_FAILED = new Pointer(-1);

    int shm_open(String name, int oflag, int mode) throws LastErrorException;

    int shm_unlink(String name) throws LastErrorException;

    /** The effective user id of this process (never fails). */
    int geteuid();

    /** Sets the process's file mode creation mask; returns the previous one (never fails). */
    int umask(int mask);

    int ftruncate(int fd, long length) throws LastErrorException;

    Pointer mmap(Pointer addr, long length, int prot, int flags, int fd, long offset) throws LastErrorException;

    int munmap(Pointer addr, long length) throws LastErrorException;

    int close(int fd) throws LastErrorException;

    int O_NOCTTY = 0400;
    int O_NOFOLLOW = 0400000;
    int O_CLOEXEC = 02000000;

    int open(String path, int oflag) throws LastErrorException;

    long read(int fd, byte[] buf, long count) throws LastErrorException;

    /** struct stat on x86-64 is 144 bytes: st_mode at 24, st_uid at 28, st_size at 48 (glibc 2.33+ exports fstat). */
    int fstat(int fd, byte[] statbuf) throws LastErrorException;

    int SEEK_END = 2;

    /** With SEEK_END and offset 0: the size of a shared-memory object. */
    long lseek(int fd, long offset, int whence) throws LastErrorException;

    /** mq_open is variadic; with O_CREAT the mode and attribute arguments follow. */
    int mq_open(String name, int oflag, int mode, MqAttr attr) throws LastErrorException;

    int mq_open(String name, int oflag) throws LastErrorException;

    int mq_close(int mqd) throws LastErrorException;

    int mq_unlink(String name) throws LastErrorException;

    int mq_timedsend(int mqd, byte[] msg, long len, int prio, Timespec abs) throws LastErrorException;

    long mq_timedreceive(int mqd, byte[] msg, long len, Pointer prio, Timespec abs) throws LastErrorException;

    int clock_gettime(int clock, Timespec ts) throws LastErrorException;

    int kill(int pid, int sig) throws LastErrorException;

    int SCHED_FIFO = 1;
    long SYS_GETTID = 186;  // x86-64

    long syscall(long number) throws LastErrorException;

    int sched_setscheduler(int pid, int policy, SchedParam param) throws LastErrorException;

    /** struct sched_param. */
    @Structure.FieldOrder({"sched_priority"})
    class SchedParam extends Structure {
        public int sched_priority;
    }

    /**
     * Puts the calling thread under SCHED_FIFO at {@code priority}.
     *
     * @return null when done, else why not (errno text)
     */
    static String fifoThisThread(int priority) {
        try {
            int tid = (int) LIBC.syscall(SYS_GETTID);
            SchedParam p = new SchedParam();
            p.sched_priority = priority;
            LIBC.sched_setscheduler(tid, SCHED_FIFO, p);
            return null;
        } catch (LastErrorException e) {
            return describe(e);
        }
    }

    /** struct timespec on x86-64. */
    @Structure.FieldOrder({"tv_sec", "tv_nsec"})
    class Timespec extends Structure {
        public long tv_sec;
        public long tv_nsec;

        /** A timespec for {@code ns} nanoseconds. */
        public static Timespec of(long ns) {
            Timespec t = new Timespec();
            t.tv_sec = ns / 1_000_000_000L;
            t.tv_nsec = ns % 1_000_000_000L;
            return t;
        }
    }

    /** struct mq_attr on x86-64 (four longs plus reserved). */
    @Structure.FieldOrder({"mq_flags", "mq_maxmsg", "mq_msgsize", "mq_curmsgs", "pad0", "pad1", "pad2", "pad3"})
    class MqAttr extends Structure {
        public long mq_flags;
        public long mq_maxmsg;
        public long mq_msgsize;
        public long mq_curmsgs;
        public long pad0;
        public long pad1;
        public long pad2;
        public long pad3;
    }

    /** CLOCK_MONOTONIC in nanoseconds (the clock the RT halves use). */
    static long monotonicNs() {
        Timespec t = new Timespec();
        LIBC.clock_gettime(CLOCK_MONOTONIC, t);
        return t.tv_sec * 1_000_000_000L + t.tv_nsec;
    }

    /** The errno of a failed call, and a text for it. */
    static String describe(LastErrorException e) {
        return "errno " + e.getErrorCode() + " (" + e.getMessage() + ")";
    }
}
