//! CRC-16/CCITT-FALSE, table-free.
//!
//! Parameters (Rocksoft model / CRC catalogue): width 16, poly `0x1021`, init `0xFFFF`,
//! refin false, refout false, xorout `0x0000`, check `0x29B1` (CRC of ASCII "123456789"),
//! residue `0x0000`. Bitwise: no 512-byte table in flash; 8 shift steps per byte is nothing
//! at 24 kB/s, and on the host a few hundred MB/s.
//!
//! Detects every error of 1, 2 or 3 bits and every burst up to 16 bits in a frame as short
//! as a bridge frame.

/// CRC-16/CCITT-FALSE of `data`.
///
/// ```
/// assert_eq!(crm100_driver::crc16_ccitt_false(b"123456789"), 0x29B1);
/// ```
pub const fn crc16_ccitt_false(data: &[u8]) -> u16 {
    crc16_ccitt_false_update(0xFFFF, data)
}

/// Continues a CRC-16/CCITT-FALSE over more bytes (`crc` = the value so far; start with
/// `0xFFFF`).
pub const fn crc16_ccitt_false_update(mut crc: u16, data: &[u8]) -> u16 {
    let mut i = 0;
    while i < data.len() {
        crc ^= (data[i] as u16) << 8;
        let mut bit = 0;
        while bit < 8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
            bit += 1;
        }
        i += 1;
    }
    crc
}
