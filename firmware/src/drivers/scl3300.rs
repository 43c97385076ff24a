//! Murata SCL3300 inclinometer over SPI (embedded-hal 1.0 `SpiDevice`): the base tilt for the
//! north finder's tilt maths (`fog_core::seeking::tilt`).
//!
//! Datasheet protocol: 32-bit frames `[OP 8 | DATA 16 | CRC 8]`, OP = RW, 5-bit address and
//! (in responses) the 2-bit return status RS; CRC-8 over the upper 24 bits, polynomial 0x1D,
//! initial 0xFF, result inverted. Off-frame: the response clocked out during request n
//! answers request n-1, so every read is pipelined and each response's address is checked
//! against the request it belongs to. RS: 00 start-up in progress, 01 normal, 10 self-test,
//! 11 error (then STATUS tells which).
//!
//! Start-up (datasheet "start-up sequence"): SW reset, wait 1 ms, select mode 4
//! (inclination, 10 Hz low-noise), enable angle outputs, wait 100 ms, read STATUS twice to
//! clear it, then a third read returns its value: RS must be 01 (normal operation).
//!
//! Angles: ANG = raw / 2^14 x 90 deg, the elevation of the sensor axis (positive up). With
//! the sensor's x on table heading 0 and y on heading 90 (mounted on the base), pitch is
//! ANG_X and roll is -asin(sin ANG_Y / cos ANG_X) (see `fog_core::seeking::tilt` for the frames).

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::SpiDevice;
use fog_core::seeking::tilt::Tilt;

pub const SW_RESET: u32 = 0xB400_2098;
pub const MODE_4: u32 = 0xB400_0338;
pub const ENABLE_ANGLES: u32 = 0xB000_1F6F;
pub const READ_STATUS: u32 = 0x1800_00E5;
pub const READ_ANG_X: u32 = 0x2400_00C7;
pub const READ_ANG_Y: u32 = 0x2800_00CD;
pub const READ_WHOAMI: u32 = 0x4000_0091;
/// WHOAMI of the SCL3300.
pub const WHOAMI: u16 = 0x00C1;

/// CRC-8 of a frame's upper 24 bits (poly 0x1D, init 0xFF, inverted), as in the datasheet.
pub fn crc8(frame_upper24: u32) -> u8 {
    let mut crc: u8 = 0xFF;
    for bit in (8..32).rev() {
        let b = ((frame_upper24 >> bit) & 1) as u8;
        let top = (crc & 0x80) ^ (b << 7);
        crc <<= 1;
        if top != 0 {
            crc ^= 0x1D;
        }
    }
    !crc
}

/// A request frame for 5-bit register `addr` (read) with its CRC.
pub fn read_request(addr: u8) -> u32 {
    let upper = ((addr as u32 & 0x1F) << 26) & 0xFFFF_FF00;
    upper | crc8(upper) as u32
}

/// A response frame split into its fields.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Response {
    pub addr: u8,
    pub rs: u8,
    pub data: u16,
}

/// Why a reading failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scl3300Error<E> {
    Spi(E),
    /// A response frame with a bad CRC.
    Crc {
        frame: u32,
    },
    /// A response for a different register than requested (lost frame sync).
    OutOfSync {
        expected_addr: u8,
        got_addr: u8,
    },
    /// Return status 11 (error) or 00 (still starting) in a response; `status` is STATUS.
    ReturnStatus {
        rs: u8,
    },
    /// WHOAMI is not 0xC1: not an SCL3300.
    WrongPart {
        whoami: u16,
    },
    /// Start-up ended without RS = 01; STATUS register value.
    StartupFailed {
        status: u16,
    },
}

impl<E> From<E> for Scl3300Error<E> {
    fn from(e: E) -> Self {
        Scl3300Error::Spi(e)
    }
}

/// Decodes and CRC-checks one response frame.
pub fn parse_response<E>(frame: u32) -> Result<Response, Scl3300Error<E>> {
    if crc8(frame & 0xFFFF_FF00) != (frame & 0xFF) as u8 {
        return Err(Scl3300Error::Crc { frame });
    }
    Ok(Response {
        addr: ((frame >> 26) & 0x1F) as u8,
        rs: ((frame >> 24) & 0x03) as u8,
        data: (frame >> 8) as u16,
    })
}

/// Angle of a raw ANG_X/ANG_Y value, deg.
pub fn angle_deg(raw: u16) -> f32 {
    raw as i16 as f32 / 16384.0 * 90.0
}

/// Base tilt from the elevations of the sensor's x and y axes, deg.
pub fn tilt_from_elevations(ang_x_deg: f32, ang_y_deg: f32) -> Tilt {
    let cx = libm::cosf(ang_x_deg.to_radians());
    let s = (libm::sinf(ang_y_deg.to_radians()) / cx).clamp(-1.0, 1.0);
    Tilt {
        pitch_deg: ang_x_deg,
        roll_deg: -libm::asinf(s).to_degrees(),
    }
}

/// The driver; `previous` is the address of the request whose answer comes next.
pub struct Scl3300<SPI> {
    spi: SPI,
    previous: u8,
}

fn addr_of(request: u32) -> u8 {
    ((request >> 26) & 0x1F) as u8
}

impl<SPI: SpiDevice> Scl3300<SPI> {
    /// Runs the start-up sequence and checks WHOAMI and the return status.
    pub fn new<D: DelayNs>(spi: SPI, delay: &mut D) -> Result<Self, Scl3300Error<SPI::Error>> {
        let mut dev = Scl3300 { spi, previous: 0 };
        dev.frame(SW_RESET)?;
        delay.delay_ms(1);
        dev.frame(MODE_4)?;
        dev.frame(ENABLE_ANGLES)?;
        delay.delay_ms(100);
        dev.frame(READ_STATUS)?;
        dev.frame(READ_STATUS)?;
        dev.frame(READ_WHOAMI)?; // answers the second STATUS read
        let whoami_resp = parse_response::<SPI::Error>(dev.frame(READ_STATUS)?)?; // answers WHOAMI
        let last = dev.frame(READ_STATUS)?; // answers STATUS
        let st = parse_response::<SPI::Error>(last)?;
        if whoami_resp.data != WHOAMI {
            return Err(Scl3300Error::WrongPart {
                whoami: whoami_resp.data,
            });
        }
        if st.rs != 0b01 {
            return Err(Scl3300Error::StartupFailed { status: st.data });
        }
        Ok(dev)
    }

    /// One 32-bit full-duplex frame: sends `request`, returns the (previous request's) answer.
    fn frame(&mut self, request: u32) -> Result<u32, Scl3300Error<SPI::Error>> {
        let mut buf = request.to_be_bytes();
        self.spi.transfer_in_place(&mut buf)?;
        self.previous = addr_of(request);
        Ok(u32::from_be_bytes(buf))
    }

    /// Sends `request` and checks that the answer belongs to the previous request.
    fn checked(&mut self, request: u32) -> Result<Response, Scl3300Error<SPI::Error>> {
        let expected = self.previous;
        let r = parse_response(self.frame(request)?)?;
        if r.addr != expected {
            return Err(Scl3300Error::OutOfSync {
                expected_addr: expected,
                got_addr: r.addr,
            });
        }
        if r.rs != 0b01 {
            return Err(Scl3300Error::ReturnStatus { rs: r.rs });
        }
        Ok(r)
    }

    /// Reads ANG_X and ANG_Y (three frames: X, Y, STATUS) and converts them to the base tilt.
    /// The STATUS frame leaves the pipeline on a known register for the next call.
    pub fn read_tilt(&mut self) -> Result<Tilt, Scl3300Error<SPI::Error>> {
        self.frame(READ_ANG_X)?; // answers the previous call's STATUS (or start-up)
        let x = self.checked(READ_ANG_Y)?;
        let y = self.checked(READ_STATUS)?;
        Ok(tilt_from_elevations(angle_deg(x.data), angle_deg(y.data)))
    }

    pub fn release(self) -> SPI {
        self.spi
    }
}
