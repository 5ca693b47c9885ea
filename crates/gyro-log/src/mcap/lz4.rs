//! LZ4 frames, as MCAP's `lz4` chunks hold them, decompressed in one call into a buffer
//! of the chunk's uncompressed size (`lz4_flex` decodes the blocks).

/// The magic number an LZ4 frame starts with.
const LZ4_FRAME_MAGIC: u32 = 0x184D_2204;
/// How far back an LZ4 match reaches: the dictionary a linked block needs.
const LZ4_WINDOW: usize = 1 << 16;

/// Decompress one LZ4 frame (the format of MCAP's `lz4` chunks), all of `frame`, into
/// exactly `out`: block by block, the output so far the dictionary of linked blocks. The
/// frame's own checksums are not verified: the chunk's CRC is, over `out`.
pub(super) fn decompress_frame(frame: &[u8], out: &mut [u8]) -> Result<(), String> {
    let u32_at = |at: usize| -> Result<u32, String> {
        frame
            .get(at..at + 4)
            .and_then(|b| Some(u32::from_le_bytes(b.try_into().ok()?)))
            .ok_or_else(|| format!("the frame ends early (byte {at} of {})", frame.len()))
    };
    if u32_at(0)? != LZ4_FRAME_MAGIC {
        return Err("not an LZ4 frame (bad magic)".into());
    }
    let flags = *frame.get(4).ok_or("the frame ends early")?;
    if flags >> 6 != 1 {
        return Err(format!(
            "LZ4 frame version {} (only 1 is known)",
            flags >> 6
        ));
    }
    if flags & 0x01 != 0 {
        return Err("the frame needs a dictionary".into());
    }
    let block_checksums = flags & 0x10 != 0;
    let content_checksum = flags & 0x04 != 0;
    let content_size = flags & 0x08 != 0;
    // Magic, flags, block descriptor, the content size if any, the header checksum.
    let mut at = 4 + 2 + if content_size { 8 } else { 0 } + 1;
    let mut written = 0;
    loop {
        let size = u32_at(at)?;
        at += 4;
        if size == 0 {
            break; // the end mark
        }
        let stored = size & 0x8000_0000 != 0;
        let len = (size & 0x7FFF_FFFF) as usize;
        let block = frame
            .get(at..at + len)
            .ok_or_else(|| format!("a block of {len} bytes overruns the frame"))?;
        at += len + if block_checksums { 4 } else { 0 };
        let (before, after) = out.split_at_mut(written);
        written += if stored {
            after
                .get_mut(..len)
                .ok_or("it decompresses to more bytes than its header says")?
                .copy_from_slice(block);
            len
        } else {
            let dictionary = &before[before.len().saturating_sub(LZ4_WINDOW)..];
            lz4_flex::block::decompress_into_with_dict(block, after, dictionary).map_err(|e| {
                match e {
                    lz4_flex::block::DecompressError::OutputTooSmall { .. } => {
                        "it decompresses to more bytes than its header says".to_string()
                    }
                    e => e.to_string(),
                }
            })?
        };
    }
    if content_checksum {
        at += 4;
    }
    if written != out.len() {
        return Err(format!(
            "it decompresses to {written} bytes, its header says {}",
            out.len()
        ));
    }
    if at != frame.len() {
        return Err(format!(
            "{} bytes after the end of its frame",
            frame.len().saturating_sub(at)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ::lz4::{BlockMode, BlockSize, ContentChecksum, EncoderBuilder};
    use std::io::Write;

    /// 600 kB of records that compress like a log's: repeated structure, varying numbers.
    fn data() -> Vec<u8> {
        let mut out = Vec::new();
        let mut x: u64 = 1;
        while out.len() < 600_000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            out.extend_from_slice(b"\x05\x1f\x00\x00\x00\x00\x00\x00\x00\x01\x00");
            out.extend_from_slice(&(x >> 40).to_le_bytes());
        }
        out
    }

    fn encode(data: &[u8], size: BlockSize, mode: BlockMode, checksums: bool) -> Vec<u8> {
        let mut builder = EncoderBuilder::new();
        builder.block_size(size).block_mode(mode);
        if checksums {
            builder
                .checksum(ContentChecksum::ChecksumEnabled)
                .block_checksum(::lz4::liblz4::BlockChecksum::BlockChecksumEnabled)
                .content_size(data.len() as u64);
        } else {
            builder.checksum(ContentChecksum::NoChecksum);
        }
        let mut encoder = builder.build(Vec::new()).unwrap();
        encoder.write_all(data).unwrap();
        let (out, result) = encoder.finish();
        result.unwrap();
        out
    }

    /// Frames from the reference C library (the `lz4` crate, which the `mcap` writer
    /// uses): linked and independent blocks, 64 kB and 4 MB blocks, with and without the
    /// checksums and the content size, and incompressible data (stored blocks).
    #[test]
    fn frames_of_the_reference_library_decode_exactly() {
        let plain = data();
        let mut noise = Vec::new();
        let mut x: u32 = 7;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            noise.push(x as u8);
        }
        for input in [&plain, &noise] {
            for size in [BlockSize::Max64KB, BlockSize::Max4MB] {
                for mode in [BlockMode::Linked, BlockMode::Independent] {
                    for checksums in [false, true] {
                        let frame = encode(input, size.clone(), mode.clone(), checksums);
                        let mut out = vec![0; input.len()];
                        decompress_frame(&frame, &mut out).unwrap();
                        assert!(out == *input, "{size:?} {mode:?} {checksums}");
                    }
                }
            }
        }
    }

    /// Damage is an error, never a panic or a short read taken as whole.
    #[test]
    fn damaged_frames_are_errors() {
        let plain = data();
        let frame = encode(&plain, BlockSize::Max64KB, BlockMode::Linked, false);
        let mut out = vec![0; plain.len()];
        let e = decompress_frame(&frame, &mut out[..plain.len() - 1]).unwrap_err();
        assert!(e.contains("more bytes than its header says"), "{e}");
        let mut longer = vec![0; plain.len() + 1];
        let e = decompress_frame(&frame, &mut longer).unwrap_err();
        assert!(e.contains("decompresses to 600"), "{e}");
        for cut in [0, 3, 6, 7, 100, frame.len() / 2, frame.len() - 1] {
            assert!(decompress_frame(&frame[..cut], &mut out).is_err(), "{cut}");
        }
        let mut extra = frame.clone();
        extra.push(0);
        let e = decompress_frame(&extra, &mut out).unwrap_err();
        assert!(e.contains("1 bytes after the end"), "{e}");
        let mut bad = frame.clone();
        bad[0] ^= 1;
        assert!(decompress_frame(&bad, &mut out)
            .unwrap_err()
            .contains("bad magic"));
        // Every byte flipped in turn: an error or other bytes (the chunk CRC's job), no panic.
        for i in (0..frame.len()).step_by(97) {
            let mut flipped = frame.clone();
            flipped[i] ^= 0x5a;
            let _ = decompress_frame(&flipped, &mut out);
        }
    }
}
