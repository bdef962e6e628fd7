// SPDX-License-Identifier: Apache-2.0
/*
 * LD_PRELOAD shim for Debian's user-mode-linux 6.1 kernel on hosts with a large XSAVE area.
 *
 * UML 6.1 saves a guest thread's FP state with PTRACE_GETREGSET(NT_X86_XSTATE) into a buffer of
 * fixed, compile-time size (the x87/SSE area, the XSAVE header and the AVX upper halves) and
 * writes it back with PTRACE_SETREGSET of the same size. The host kernel accepts a SETREGSET of
 * the XSAVE area only at its full size (x86 xstateregs_set: count must equal the user xstate
 * size), and on a CPU with AVX-512 or AMX that size is larger than UML's buffer: the write fails
 * with EFAULT, UML prints "ptrace set fp regs failed, errno = 14" and the guest's init dies.
 * Upstream UML reads the host's XSAVE size at run time since the regset rework (2024); 6.1 does
 * not.
 *
 * This shim makes such a short SETREGSET whole: it reads the tracee's current full XSAVE area,
 * lays UML's bytes over its start (x87/SSE, header, AVX upper halves: everything UML saved) and
 * writes the full area. The components past UML's buffer (AVX-512, PKRU, AMX) keep the tracee's
 * own current values: they are not switched between the threads of one guest process, so
 * tools/with-vcan also tells the guest's glibc not to use AVX-512 (GLIBC_TUNABLES).
 * Every other ptrace request passes through untouched. tools/with-vcan builds it and preloads
 * it into the UML kernel process only (never into the guest's programs).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <elf.h>
#include <errno.h>
#include <stdarg.h>
#include <string.h>
#include <sys/ptrace.h>
#include <sys/types.h>
#include <sys/uio.h>

typedef long (*ptrace_fn)(enum __ptrace_request, pid_t, void *, void *);

long ptrace(enum __ptrace_request request, ...)
{
	va_list ap;
	va_start(ap, request);
	pid_t pid = va_arg(ap, pid_t);
	void *addr = va_arg(ap, void *);
	void *data = va_arg(ap, void *);
	va_end(ap);

	static ptrace_fn real;
	if (!real) {
		real = (ptrace_fn)dlsym(RTLD_NEXT, "ptrace");
		if (!real) {
			errno = ENOSYS;
			return -1;
		}
	}
	/* The host's XSAVE size is a constant: learnt from the first read, so a write that is already
	 * whole (every write, on hosts without AVX-512 or AMX) costs no extra read. */
	static size_t host_size;
	struct iovec *given = data;
	if (request == PTRACE_SETREGSET && (unsigned long)addr == NT_X86_XSTATE && given &&
	    (host_size == 0 || given->iov_len < host_size)) {
		/* The largest XSAVE area today (AMX) is about 11 KiB. */
		static _Thread_local unsigned char full[64 * 1024] __attribute__((aligned(64)));
		struct iovec whole = {full, sizeof full};
		if (real(PTRACE_GETREGSET, pid, (void *)(unsigned long)NT_X86_XSTATE, &whole) < 0)
			return -1;
		host_size = whole.iov_len;
		if (given->iov_len < whole.iov_len) {
			memcpy(full, given->iov_base, given->iov_len);
			return real(PTRACE_SETREGSET, pid, addr, &whole);
		}
	}
	return real(request, pid, addr, data);
}
