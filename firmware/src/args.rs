//! The firmware's command line, from semihosting (`SYS_GET_CMDLINE`; QEMU passes
//! `-semihosting-config …,arg=fw,arg=IN,arg=OUT` as `"fw IN OUT"`).
//!
//! `fw [IN [OUT]]` processes IN (default `stream.bin`) into OUT (default `results.bin`);
//! `fw --realtime=BYTES_PER_S IN OUT` processes IN delivered by a timer interrupt at that
//! rate (the real-time run under QEMU's `-icount`); `fw --usart=BYTES` processes a stream of BYTES bytes arriving on USART3 into packets sent
//! on USART6 (QEMU's `-serial` chardevs); `fw --selftest=overflow|hardfault|panic` provokes
//! that failure, to check that each one ends the run with a non-zero exit instead of a hang
//! or a silent success.

use core::ffi::CStr;

/// What the run should do.
#[derive(Debug, PartialEq, Eq)]
pub enum Command<'a> {
    /// Process `input` into `output`.
    Process {
        /// The input stream's host path.
        input: &'a CStr,
        /// The output file's host path.
        output: &'a CStr,
    },
    /// Process a stream of `bytes` bytes from USART3 into packets on USART6.
    Usart {
        /// The stream's length: the run ends once this many bytes have arrived.
        bytes: u64,
    },
    /// Process `input` into `output` with the stream delivered by a timer interrupt at
    /// `bytes_per_s` bytes per second of the board's time (`fw --realtime=BYTES_PER_S IN OUT`).
    Realtime {
        /// Delivery rate, bytes per second.
        bytes_per_s: u32,
        /// The input stream's host path.
        input: &'a CStr,
        /// The output file's host path.
        output: &'a CStr,
    },
    /// Overflow the stack (it must fault: the stack lies below the statics).
    SelfTestOverflow,
    /// Read from unmapped memory (the HardFault handler must exit non-zero).
    SelfTestHardFault,
    /// Panic (the panic handler must exit non-zero).
    SelfTestPanic,
}

/// Why the command line was not understood.
#[derive(Debug, PartialEq, Eq)]
pub enum ArgsError {
    /// More than two file names.
    TooManyArguments,
    /// An option other than the self-tests and `--usart=BYTES`.
    UnknownOption,
    /// `--usart=` without a whole number of bytes.
    BadByteCount,
}

/// Parses the command line held in `buf[..len]` in place: the words' separators become NULs,
/// so the file names are borrowed from `buf` as C strings without copying. The first word is
/// the program name. `buf` must have room for one byte after the line.
pub fn parse(buf: &mut [u8], len: usize) -> Result<Command<'_>, ArgsError> {
    let len = len.min(buf.len().saturating_sub(1));
    for b in &mut buf[..len] {
        if *b == b' ' {
            *b = 0;
        }
    }
    if let Some(b) = buf.get_mut(len) {
        *b = 0;
    }
    let buf = &*buf;
    let mut words = buf[..=len]
        .split_inclusive(|&b| b == 0)
        .filter(|w| w.len() > 1)
        .skip(1)
        .filter_map(|w| CStr::from_bytes_with_nul(w).ok());
    let first = words.next();
    let second = words.next();
    let third = words.next();
    if let Some(rate) = first.and_then(|w| w.to_bytes().strip_prefix(b"--realtime=")) {
        let bytes_per_s = core::str::from_utf8(rate)
            .ok()
            .and_then(|c| c.parse().ok())
            .filter(|&r: &u32| r > 0)
            .ok_or(ArgsError::BadByteCount)?;
        if words.next().is_some() {
            return Err(ArgsError::TooManyArguments);
        }
        return Ok(Command::Realtime {
            bytes_per_s,
            input: second.unwrap_or(c"stream.bin"),
            output: third.unwrap_or(c"results.bin"),
        });
    }
    if third.is_some() {
        return Err(ArgsError::TooManyArguments);
    }
    if let Some(opt) = first.filter(|w| w.to_bytes().starts_with(b"--")) {
        if let Some(count) = opt.to_bytes().strip_prefix(b"--usart=") {
            return core::str::from_utf8(count)
                .ok()
                .and_then(|c| c.parse().ok())
                .map(|bytes| Command::Usart { bytes })
                .ok_or(ArgsError::BadByteCount);
        }
        return match opt.to_bytes() {
            b"--selftest=overflow" => Ok(Command::SelfTestOverflow),
            b"--selftest=hardfault" => Ok(Command::SelfTestHardFault),
            b"--selftest=panic" => Ok(Command::SelfTestPanic),
            _ => Err(ArgsError::UnknownOption),
        };
    }
    Ok(Command::Process {
        input: first.unwrap_or(c"stream.bin"),
        output: second.unwrap_or(c"results.bin"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(s: &str) -> Result<Command<'static>, ArgsError> {
        let buf: &'static mut [u8] = Box::leak(vec![0u8; s.len() + 1].into_boxed_slice());
        buf[..s.len()].copy_from_slice(s.as_bytes());
        parse(buf, s.len())
    }

    #[test]
    fn file_names_in_place_with_defaults() {
        assert_eq!(
            parse_str("fw /tmp/a.bin /tmp/out.bin"),
            Ok(Command::Process {
                input: c"/tmp/a.bin",
                output: c"/tmp/out.bin"
            })
        );
        assert_eq!(
            parse_str("fw  in.bin"),
            Ok(Command::Process {
                input: c"in.bin",
                output: c"results.bin"
            })
        );
        assert_eq!(
            parse_str(""),
            Ok(Command::Process {
                input: c"stream.bin",
                output: c"results.bin"
            })
        );
    }

    #[test]
    fn self_tests_and_errors() {
        assert_eq!(
            parse_str("fw --selftest=overflow"),
            Ok(Command::SelfTestOverflow)
        );
        assert_eq!(
            parse_str("fw --selftest=hardfault"),
            Ok(Command::SelfTestHardFault)
        );
        assert_eq!(parse_str("fw --selftest=panic"), Ok(Command::SelfTestPanic));
        assert_eq!(parse_str("fw --bogus"), Err(ArgsError::UnknownOption));
        assert_eq!(
            parse_str("fw --usart=123456"),
            Ok(Command::Usart { bytes: 123456 })
        );
        assert_eq!(parse_str("fw --usart="), Err(ArgsError::BadByteCount));
        assert_eq!(parse_str("fw --usart=-1"), Err(ArgsError::BadByteCount));
        assert_eq!(parse_str("fw --usart"), Err(ArgsError::UnknownOption));
        assert_eq!(parse_str("fw a b c"), Err(ArgsError::TooManyArguments));
        assert_eq!(
            parse_str("fw --realtime=4075000 in.bin out.bin"),
            Ok(Command::Realtime {
                bytes_per_s: 4_075_000,
                input: c"in.bin",
                output: c"out.bin"
            })
        );
        assert_eq!(
            parse_str("fw --realtime=0 a b"),
            Err(ArgsError::BadByteCount)
        );
        assert_eq!(
            parse_str("fw --realtime=9 a b c"),
            Err(ArgsError::TooManyArguments)
        );
    }

    #[test]
    fn a_line_filling_the_buffer_is_cut_not_overrun() {
        let mut buf = *b"fw abcdef";
        // Reported length longer than the buffer: the last byte becomes the terminator.
        assert_eq!(
            parse(&mut buf, 50),
            Ok(Command::Process {
                input: c"abcde",
                output: c"results.bin"
            })
        );
    }
}
