//! Files on the host through ARM semihosting (`SYS_OPEN`/`SYS_READ`/`SYS_WRITE`), behind
//! `embedded_io::{Read, Write}` so the processing loop never sees semihosting: on a board, a
//! UART or DMA driver implementing the same two traits takes this module's place.
//!
//! Semihosting calls are `BKPT 0xAB` traps that QEMU (`-semihosting-config enable=on`)
//! or a debug probe services; without a debugger attached on real hardware they fault, so
//! this module is for QEMU and bench runs only.

use cortex_m_semihosting::{nr, syscall};

/// A semihosting call failed; carries the call number and the host's return value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SemihostingError {
    /// The semihosting operation number (`SYS_OPEN` = 1, …).
    pub op: u8,
    /// What the host returned (−1 for open errors; bytes not transferred for read/write).
    pub ret: isize,
}

impl core::fmt::Display for SemihostingError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "semihosting operation {} failed (returned {})",
            self.op, self.ret
        )
    }
}

impl core::error::Error for SemihostingError {}

impl embedded_io::Error for SemihostingError {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}

/// How to open a host file (the ISO C `fopen` modes semihosting uses, binary variants).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// `"rb"`.
    ReadBinary = 1,
    /// `"wb"` (create or truncate).
    WriteBinary = 5,
}

/// An open host file.
pub struct HostFile {
    handle: usize,
}

impl HostFile {
    /// Opens `name` (NUL-terminated path, relative to QEMU's working directory).
    pub fn open(name: &core::ffi::CStr, mode: Mode) -> Result<Self, SemihostingError> {
        let bytes = name.to_bytes();
        // SAFETY: SYS_OPEN reads `len` bytes of the NUL-terminated string at `ptr`; both
        // outlive the call.
        let ret = unsafe { syscall!(OPEN, bytes.as_ptr(), mode as usize, bytes.len()) };
        if ret as isize == -1 {
            return Err(SemihostingError {
                op: nr::OPEN as u8,
                ret: -1,
            });
        }
        Ok(Self { handle: ret })
    }
}

impl Drop for HostFile {
    fn drop(&mut self) {
        // SAFETY: closes a handle this value owns; nothing uses it afterwards.
        unsafe {
            syscall!(CLOSE, self.handle);
        }
    }
}

impl embedded_io::ErrorType for HostFile {
    type Error = SemihostingError;
}

impl embedded_io::Read for HostFile {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        if buf.is_empty() {
            return Ok(0);
        }
        // SAFETY: SYS_READ writes at most `buf.len()` bytes into `buf`, which we borrow
        // mutably for the duration of the call.
        let not_read = unsafe { syscall!(READ, self.handle, buf.as_mut_ptr(), buf.len()) };
        // SYS_READ returns the number of bytes *not* read (0 = all, len = end of file).
        match buf.len().checked_sub(not_read) {
            Some(n) => Ok(n),
            None => Err(SemihostingError {
                op: nr::READ as u8,
                ret: not_read as isize,
            }),
        }
    }
}

impl embedded_io::Write for HostFile {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        if buf.is_empty() {
            return Ok(0);
        }
        // SAFETY: SYS_WRITE reads `buf.len()` bytes from `buf`.
        let not_written = unsafe { syscall!(WRITE, self.handle, buf.as_ptr(), buf.len()) };
        match buf.len().checked_sub(not_written) {
            Some(n) if n > 0 => Ok(n),
            _ => Err(SemihostingError {
                op: nr::WRITE as u8,
                ret: not_written as isize,
            }),
        }
    }

    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// The command line QEMU passes with `-semihosting-config …,arg=A,arg=B` (`SYS_GET_CMDLINE`),
/// written into `buf`; returns the bytes without the terminating NUL.
pub fn command_line(buf: &mut [u8]) -> Result<&mut [u8], SemihostingError> {
    // The parameter block is read *and written* by the host: [buffer, length in/out].
    let mut block: [usize; 2] = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: the host writes at most `buf.len()` bytes into `buf` and the new length into
    // `block[1]`; both live across the call.
    let ret =
        unsafe { cortex_m_semihosting::syscall1(nr::GET_CMDLINE, block.as_mut_ptr() as usize) };
    if ret != 0 || block[1] > buf.len() {
        return Err(SemihostingError {
            op: nr::GET_CMDLINE as u8,
            ret: ret as isize,
        });
    }
    Ok(&mut buf[..block[1]])
}
