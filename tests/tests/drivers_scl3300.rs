//! Host tests of the SCL3300 inclinometer driver against embedded-hal-mock's SPI: the
//! datasheet's frames and CRC, the start-up sequence, the off-frame pipeline, and every
//! fault (CRC, lost sync, error return status, wrong part) turned into an error.

use embedded_hal_mock::eh1::delay::NoopDelay;
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use fog_firmware::drivers::scl3300::{
    crc8, read_request, Scl3300, Scl3300Error, ENABLE_ANGLES, MODE_4, READ_ANG_X, READ_ANG_Y,
    READ_STATUS, READ_WHOAMI, SW_RESET, WHOAMI,
};

const ADDR_STATUS: u8 = 0x06;
const ADDR_ANG_X: u8 = 0x09;
const ADDR_ANG_Y: u8 = 0x0A;
const ADDR_WHOAMI: u8 = 0x10;

/// A device response frame with a valid CRC.
fn resp(addr: u8, rs: u8, data: u16) -> u32 {
    let upper = ((addr as u32) << 26) | ((rs as u32) << 24) | ((data as u32) << 8);
    upper | crc8(upper) as u32
}

/// One SpiDevice transfer: request out, response in.
fn frame(request: u32, response: u32) -> Vec<Transaction<u8>> {
    vec![
        Transaction::transaction_start(),
        Transaction::transfer_in_place(
            request.to_be_bytes().to_vec(),
            response.to_be_bytes().to_vec(),
        ),
        Transaction::transaction_end(),
    ]
}

fn startup(whoami: u16, final_rs: u8) -> Vec<Transaction<u8>> {
    [
        frame(SW_RESET, 0xFFFF_FFFF), // undefined answer to the frame before power-on
        frame(MODE_4, resp(0x2D, 0b00, 0)),
        frame(ENABLE_ANGLES, resp(0x2D, 0b00, 0)),
        frame(READ_STATUS, resp(0x2C, 0b00, 0)),
        frame(READ_STATUS, resp(ADDR_STATUS, 0b11, 0x0012)), // start-up flags, cleared by reading
        frame(READ_WHOAMI, resp(ADDR_STATUS, 0b01, 0)),
        frame(READ_STATUS, resp(ADDR_WHOAMI, 0b01, whoami)),
        frame(READ_STATUS, resp(ADDR_STATUS, final_rs, 0)),
    ]
    .concat()
}

#[test]
fn datasheet_frames_have_datasheet_crcs() {
    for f in [
        SW_RESET,
        MODE_4,
        ENABLE_ANGLES,
        READ_STATUS,
        READ_ANG_X,
        READ_ANG_Y,
        READ_WHOAMI,
    ] {
        assert_eq!(crc8(f & 0xFFFF_FF00), (f & 0xFF) as u8, "{f:#010x}");
    }
    assert_eq!(read_request(ADDR_ANG_X), READ_ANG_X);
    assert_eq!(read_request(ADDR_STATUS), READ_STATUS);
}

#[test]
fn startup_then_tilt_reads_follow_the_off_frame_pipeline() {
    // ANG_X = +5 deg (5/90 x 2^14 = 910.2 -> 910), ANG_Y = -3 deg (-546).
    let x_raw = 910i16 as u16;
    let y_raw = (-546i16) as u16;
    let mut tx = startup(WHOAMI, 0b01);
    tx.extend(frame(READ_ANG_X, resp(ADDR_STATUS, 0b01, 0)));
    tx.extend(frame(READ_ANG_Y, resp(ADDR_ANG_X, 0b01, x_raw)));
    tx.extend(frame(READ_STATUS, resp(ADDR_ANG_Y, 0b01, y_raw)));
    let mut dev = Scl3300::new(Mock::new(&tx), &mut NoopDelay).expect("start-up passes");
    let t = dev.read_tilt().unwrap();
    assert!((t.pitch_deg - 4.998).abs() < 0.001, "{t:?}");
    // roll = -asin(sin(-2.999 deg) / cos(4.998 deg)) = +3.011 deg.
    assert!((t.roll_deg - 3.0105).abs() < 0.001, "{t:?}");
    dev.release().done();
}

#[test]
fn a_corrupted_response_is_a_crc_error_not_a_value() {
    let mut tx = startup(WHOAMI, 0b01);
    tx.extend(frame(READ_ANG_X, resp(ADDR_STATUS, 0b01, 0)));
    tx.extend(frame(READ_ANG_Y, resp(ADDR_ANG_X, 0b01, 910) ^ 0x0000_0400));
    let mut dev = Scl3300::new(Mock::new(&tx), &mut NoopDelay).unwrap();
    assert!(matches!(dev.read_tilt(), Err(Scl3300Error::Crc { .. })));
    dev.release().done();
}

#[test]
fn error_status_and_lost_sync_are_reported() {
    let mut tx = startup(WHOAMI, 0b01);
    tx.extend(frame(READ_ANG_X, resp(ADDR_STATUS, 0b01, 0)));
    tx.extend(frame(READ_ANG_Y, resp(ADDR_ANG_X, 0b11, 910)));
    // Next call: the answer is for ANG_Y although STATUS was asked last time.
    tx.extend(frame(READ_ANG_X, resp(ADDR_ANG_Y, 0b01, 0)));
    tx.extend(frame(READ_ANG_Y, resp(ADDR_ANG_Y, 0b01, 0)));
    let mut dev = Scl3300::new(Mock::new(&tx), &mut NoopDelay).unwrap();
    assert_eq!(
        dev.read_tilt(),
        Err(Scl3300Error::ReturnStatus { rs: 0b11 })
    );
    assert_eq!(
        dev.read_tilt(),
        Err(Scl3300Error::OutOfSync {
            expected_addr: ADDR_ANG_X,
            got_addr: ADDR_ANG_Y
        })
    );
    dev.release().done();
}

#[test]
fn startup_refuses_a_wrong_part_or_a_failed_status() {
    let tx = startup(0x0081, 0b01);
    let mut spi = Mock::new(&tx);
    assert_eq!(
        Scl3300::new(spi.clone(), &mut NoopDelay).err(),
        Some(Scl3300Error::WrongPart { whoami: 0x0081 })
    );
    spi.done();
    let tx = startup(WHOAMI, 0b11);
    let mut spi = Mock::new(&tx);
    assert!(matches!(
        Scl3300::new(spi.clone(), &mut NoopDelay).err(),
        Some(Scl3300Error::StartupFailed { .. })
    ));
    spi.done();
}
