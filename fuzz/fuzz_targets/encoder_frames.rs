//! The encoder driver on any stream of response frames and any mounting: no panic, and
//! every position within half a turn of travel.
#![no_main]
use arbitrary::Arbitrary;
use embedded_hal::spi::{ErrorType, Operation, SpiDevice};
use libfuzzer_sys::fuzz_target;
use mccs_firmware::drivers::as5047p::{As5047p, EncoderConfig};

#[derive(Arbitrary, Debug)]
struct Input {
    zero: u16,
    mm_per_count: f64,
    max_step: u16,
    diag_every: u16,
    frames: Vec<Option<u16>>,
}

struct Stream(std::vec::IntoIter<Option<u16>>);

impl ErrorType for Stream {
    type Error = embedded_hal::spi::ErrorKind;
}

impl SpiDevice<u8> for Stream {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let frame = self.0.next().flatten().ok_or(embedded_hal::spi::ErrorKind::Other)?;
        for op in ops {
            if let Operation::Transfer(rx, _) = op {
                let b = frame.to_be_bytes();
                for (k, r) in rx.iter_mut().enumerate() {
                    *r = b[k % 2];
                }
            }
        }
        Ok(())
    }
}

fuzz_target!(|i: Input| {
    let n = i.frames.len();
    let config = EncoderConfig {
        zero: i.zero,
        mm_per_count: i.mm_per_count,
        max_step: i.max_step,
        diag_every: i.diag_every,
    };
    let limit = 8192.0 * 0.01 + 1e-3;
    let mut enc = As5047p::new(Stream(i.frames.into_iter()), config);
    for _ in 0..n {
        if let Ok(z) = enc.read() {
            assert!(z.to_num::<f64>().abs() <= limit, "{z}");
        }
    }
    let _ = enc.errors();
});
