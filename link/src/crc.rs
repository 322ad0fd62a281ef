//! CRC-32 (IEEE 802.3: reflected polynomial `0xEDB88320`, initial and final value
//! `0xFFFFFFFF`), the one of zlib and Ethernet; its check value, the CRC of `123456789`,
//! is `0xCBF43926` (tested). A frame's CRC catches every burst of up to 32 corrupted
//! bits, so that a corrupted frame is dropped and counted, never taken for another
//! valid message (COBS and postcard alone decode many single-byte corruptions of a
//! small frame as a different message: docs/link.md).

/// The byte-wise lookup table, built at compile time (1 KiB of flash).
const TABLE: [u32; 256] = table();

const fn table() -> [u32; 256] {
    let mut t = [0u32; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
}

/// The CRC-32 of `bytes`.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c = TABLE[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8);
    }
    c ^ 0xFFFF_FFFF
}
