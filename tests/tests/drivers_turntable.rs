//! Host tests of the serial turntable driver against embedded-hal-mock's UART: the
//! command/reply protocol, position polling, and every fault (timeouts, NAK, controller
//! fault, position fault, move timeout) reported as an error.

use std::cell::Cell;

use embedded_hal_mock::eh1::serial::{Mock, Transaction};
use embedded_hal_nb::nb;
use fog_core::hal::{TableState, Turntable};
use fog_firmware::drivers::turntable::{SerialTurntable, TurntableConfig, TurntableError};

fn idle() -> Transaction<u8> {
    Transaction::read_error(nb::Error::WouldBlock)
}

fn reply(line: &str) -> [Transaction<u8>; 2] {
    [Transaction::read_many(line.as_bytes()), idle()]
}

/// A reply that ends the poll with an error: the driver stops reading at it.
fn fatal(line: &str) -> Transaction<u8> {
    Transaction::read_many(line.as_bytes())
}

fn sends(line: &str) -> Transaction<u8> {
    Transaction::write_many(line.as_bytes())
}

fn table<'c>(
    tx: &[Transaction<u8>],
    clock: &'c Cell<f64>,
) -> SerialTurntable<Mock<u8>, &'c Cell<f64>> {
    SerialTurntable::new(Mock::new(tx), clock, TurntableConfig::default())
}

#[test]
fn move_polls_position_until_settled() {
    let mut tx = vec![sends("MOV 180.000\r")];
    tx.extend(reply("ACK\r"));
    tx.extend([idle(), sends("POS?\r")]);
    tx.extend(reply("POS 90.125 M\r\n"));
    tx.extend([idle(), sends("POS?\r")]);
    tx.extend(reply("POS 180.002 S\r"));
    let clock = Cell::new(100.0);
    let mut t = table(&tx, &clock);
    t.command_heading(180.0).unwrap();
    assert_eq!(t.poll(), Ok(TableState::Moving)); // ACK
    clock.set(100.15);
    assert_eq!(t.poll(), Ok(TableState::Moving)); // sends POS?
    assert_eq!(t.poll(), Ok(TableState::Moving)); // POS ... M
    clock.set(100.3);
    assert_eq!(t.poll(), Ok(TableState::Moving)); // sends POS?
    assert_eq!(
        t.poll(),
        Ok(TableState::Settled {
            heading_deg: 180.002
        })
    );
    t.release().done();
}

#[test]
fn headings_are_wrapped_into_0_360() {
    let tx = [sends("MOV 270.000\r"), sends("MOV 0.500\r")];
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(-90.0).unwrap();
    t.command_heading(360.5).unwrap();
    assert_eq!(t.command_heading(f32::NAN), Err(TurntableError::BadHeading));
    t.release().done();
}

#[test]
fn missing_ack_times_out_and_stays_failed() {
    let tx = [sends("MOV 45.000\r"), idle(), idle(), idle()];
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(45.0).unwrap();
    assert_eq!(t.poll(), Ok(TableState::Moving));
    clock.set(0.6);
    assert_eq!(t.poll(), Err(TurntableError::Timeout));
    assert_eq!(t.poll(), Err(TurntableError::Timeout), "no silent recovery");
    t.release().done();
}

#[test]
fn missing_position_reply_times_out() {
    let mut tx = vec![sends("MOV 45.000\r")];
    tx.extend(reply("ACK\r"));
    tx.extend([idle(), sends("POS?\r"), idle()]);
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(45.0).unwrap();
    t.poll().unwrap();
    clock.set(0.2);
    t.poll().unwrap();
    clock.set(0.71);
    assert_eq!(t.poll(), Err(TurntableError::Timeout));
    t.release().done();
}

#[test]
fn nak_and_controller_faults_are_reported() {
    let mut tx = vec![sends("MOV 10.000\r")];
    tx.push(fatal("NAK\r"));
    tx.push(sends("MOV 10.000\r"));
    tx.extend(reply("ACK\r"));
    tx.extend([idle(), sends("POS?\r")]);
    tx.push(fatal("POS 3.500 F7\r"));
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(10.0).unwrap();
    assert_eq!(t.poll(), Err(TurntableError::Rejected));
    t.command_heading(10.0).unwrap();
    t.poll().unwrap();
    clock.set(0.2);
    t.poll().unwrap();
    assert_eq!(t.poll(), Err(TurntableError::Fault(7)));
    t.release().done();
}

#[test]
fn settling_off_target_is_a_position_fault() {
    let mut tx = vec![sends("MOV 0.000\r")];
    tx.extend(reply("ACK\r"));
    tx.extend([idle(), sends("POS?\r")]);
    tx.push(fatal("POS 359.950 S\r"));
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(0.0).unwrap();
    t.poll().unwrap();
    clock.set(0.2);
    t.poll().unwrap();
    assert_eq!(
        t.poll(),
        Err(TurntableError::PositionFault {
            commanded_deg: 0.0,
            actual_deg: 359.95
        })
    );
    t.release().done();
}

#[test]
fn a_table_that_never_settles_hits_the_move_timeout() {
    let clock = Cell::new(0.0);
    let mut tx = vec![sends("MOV 90.000\r")];
    tx.extend(reply("ACK\r"));
    // Moving forever: reply M to every query, polled every 0.11 s until 29.92 s.
    let polls = 272;
    for _ in 0..polls {
        tx.extend([idle(), sends("POS?\r")]);
        tx.extend(reply("POS 45.000 M\r"));
    }
    tx.push(idle());
    let mut t = table(&tx, &clock);
    t.command_heading(90.0).unwrap();
    t.poll().unwrap();
    for i in 1..=polls {
        clock.set(0.11 * i as f64);
        assert_eq!(t.poll(), Ok(TableState::Moving));
        assert_eq!(t.poll(), Ok(TableState::Moving));
    }
    clock.set(30.2);
    assert_eq!(t.poll(), Err(TurntableError::MoveTimeout));
    t.release().done();
}

#[test]
fn garbled_replies_are_errors() {
    let mut tx = vec![sends("MOV 1.000\r")];
    tx.extend(reply("ACK\r"));
    tx.extend([idle(), sends("POS?\r")]);
    tx.push(fatal("POS 1.0x0 S\r"));
    let clock = Cell::new(0.0);
    let mut t = table(&tx, &clock);
    t.command_heading(1.0).unwrap();
    t.poll().unwrap();
    clock.set(0.2);
    t.poll().unwrap();
    assert_eq!(t.poll(), Err(TurntableError::Garbled));
    t.release().done();
}
