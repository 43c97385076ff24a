//! Host tests of the TMP117 driver against embedded-hal-mock's I2C: the datasheet's
//! register map and conversions, and every fault turned into an error, never a value.

use std::cell::Cell;

use embedded_hal::i2c::{ErrorKind, NoAcknowledgeSource};
use embedded_hal_mock::eh1::i2c::{Mock, Transaction};
use fog_core::hal::TemperatureSensor;
use fog_firmware::drivers::tmp117::{
    raw_to_celsius, I2cFault, Tmp117, Tmp117Error, DEFAULT_ADDRESS as A, REG_CONFIGURATION,
    REG_DEVICE_ID, REG_TEMP_RESULT,
};

fn init_transactions() -> Vec<Transaction> {
    vec![
        // Device_ID reads 0x0117 (revision 0).
        Transaction::write_read(A, vec![REG_DEVICE_ID], vec![0x01, 0x17]),
        // Continuous conversion, CONV=100, AVG=01 (8): 0x0220, big-endian.
        Transaction::write(A, vec![REG_CONFIGURATION, 0x02, 0x20]),
    ]
}

fn temp_read(msb: u8, lsb: u8) -> Transaction {
    Transaction::write_read(A, vec![REG_TEMP_RESULT], vec![msb, lsb])
}

#[test]
fn init_checks_id_then_reads_datasheet_values() {
    let mut tx = init_transactions();
    tx.push(temp_read(0x0C, 0x80)); // +25.0 degC
    tx.push(temp_read(0xEC, 0x00)); // -40.0 degC
    tx.push(temp_read(0x00, 0x01)); // +7.8125 m degC, one LSB
    let clock = Cell::new(12.5);
    let mut dev = Tmp117::new(Mock::new(&tx), A, &clock).expect("a TMP117 answers");
    let s = dev.read_temp().unwrap();
    assert_eq!((s.t_s, s.temp_c), (12.5, 25.0));
    clock.set(13.5);
    let s = dev.read_temp().unwrap();
    assert_eq!((s.t_s, s.temp_c), (13.5, -40.0));
    assert_eq!(dev.read_temp().unwrap().temp_c, 0.007_812_5);
    dev.release().done();
}

#[test]
fn a_newer_silicon_revision_is_accepted() {
    let tx = [
        Transaction::write_read(A, vec![REG_DEVICE_ID], vec![0x11, 0x17]),
        Transaction::write(A, vec![REG_CONFIGURATION, 0x02, 0x20]),
    ];
    let dev = Tmp117::new(Mock::new(&tx), A, Cell::new(0.0)).expect("rev 1 is a TMP117");
    dev.release().done();
}

#[test]
fn wrong_part_is_rejected_at_init() {
    // An ADT7420 or similar answering at the same address.
    let tx = [Transaction::write_read(
        A,
        vec![REG_DEVICE_ID],
        vec![0x00, 0xCB],
    )];
    let mut mock = Mock::new(&tx);
    let err = Tmp117::new(mock.clone(), A, Cell::new(0.0)).err();
    assert_eq!(err, Some(Tmp117Error::WrongDevice { id: 0x00CB }));
    mock.done();
}

#[test]
fn silent_sensor_is_a_bus_error_not_a_temperature() {
    let nack = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
    let mut tx = init_transactions();
    tx.push(temp_read(0x0C, 0x80).with_error(nack));
    tx.push(temp_read(0x0C, 0x80)); // it comes back
    let mut dev = Tmp117::new(Mock::new(&tx), A, Cell::new(0.0)).unwrap();
    assert_eq!(
        dev.read_temp(),
        Err(Tmp117Error::Bus(I2cFault::NoAcknowledge))
    );
    assert_eq!(dev.read_temp().unwrap().temp_c, 25.0);
    dev.release().done();
}

#[test]
fn reset_value_and_out_of_range_readings_are_faults() {
    let mut tx = init_transactions();
    tx.push(temp_read(0x80, 0x00)); // reset value: no conversion yet
    tx.push(temp_read(0x4B, 0x01)); // 150.0078 degC: past the specified range
    let mut dev = Tmp117::new(Mock::new(&tx), A, Cell::new(0.0)).unwrap();
    assert_eq!(dev.read_temp(), Err(Tmp117Error::NotReady));
    assert_eq!(
        dev.read_temp(),
        Err(Tmp117Error::OutOfRange { raw: 0x4B01 })
    );
    dev.release().done();
}

#[test]
fn range_edges_follow_the_datasheet() {
    assert_eq!(raw_to_celsius(0x4B00), Ok(150.0));
    assert_eq!(raw_to_celsius(0xE480), Ok(-55.0));
    assert_eq!(
        raw_to_celsius(0xE47F),
        Err(Tmp117Error::OutOfRange { raw: 0xE47F })
    );
    assert_eq!(
        raw_to_celsius(0x7FFF),
        Err(Tmp117Error::OutOfRange { raw: 0x7FFF })
    );
    for raw in 0xE480u16..=0xFFFF {
        let t = raw_to_celsius(raw).unwrap();
        assert_eq!(t, f32::from(raw as i16) / 128.0);
    }
}
