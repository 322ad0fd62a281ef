//! The run's semihosting command line (QEMU's `-semihosting-config …,arg=A,arg=B`), for
//! the runs the test command starts with an argument: the bench's `budget-test`, the
//! board's injected fault. Only where a semihosting host answers (QEMU, or a debugger
//! that serves it): without one the call stops the core.

/// The command line, read into `buf`, as its space-separated words; empty where it
/// cannot be read (no line, or longer than `buf`).
pub fn words(buf: &mut [u8]) -> impl Iterator<Item = &[u8]> {
    // SYS_GET_CMDLINE's block: the buffer and its length, which the host replaces with
    // the length it wrote.
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: the host writes at most `block[1]` bytes to `block[0]`, a live buffer, and
    // one word to `block[1]`; the call has no other effect.
    let failed = unsafe {
        cortex_m_semihosting::syscall1(
            cortex_m_semihosting::nr::GET_CMDLINE,
            block.as_mut_ptr() as usize,
        )
    } != 0;
    let len = if failed { 0 } else { block[1].min(buf.len()) };
    buf[..len].split(|&b| b == b' ').filter(|w| !w.is_empty())
}
