//! The field log: a ring of field records (one per completed two-position seek) in NOR
//! flash that survives power cuts, so the host can pull what the device learnt in the
//! field (`fogsim field pull`) and refine the drift model (issue 20 item 4).
//!
//! Layout: the region is whole erase sectors (at least two), each cut into fixed slots of
//! `FIELD_RECORD_LEN` bytes (`fog_core::seeking::field_record`: magic, version, values,
//! sequence and a CRC-32 of its own). Records are appended in slot order, wrapping from
//! the last sector to the first; a slot is written once per erase.
//!
//! - Boot (`open`): every slot is read; the newest valid record (highest sequence) fixes
//!   the next sequence, and the write cursor is the first erased slot after it. A slot
//!   that is neither erased nor a valid record (a write cut by a power loss) is skipped,
//!   never returned and never written over.
//! - Append: when the cursor enters a sector, that sector (holding the oldest records)
//!   is erased first; a sector with a torn erase is erased again. At least
//!   `sectors - 1` sectors of records are always kept.
//! - Read (`read_from`): the records with sequence >= `from`, oldest first, a bounded
//!   number per call (one link reply), by a scan of the slots (no index in RAM, so
//!   nothing to get out of step with the flash).
//!
//! The flash is any `embedded-storage` `NorFlash` (the QEMU build's region is mirrored
//! into a host file by `store::mirrored`, like the model store).

use embedded_storage::nor_flash::NorFlash;
use fog_core::link::messages::{FieldRecordBatch, MAX_FIELD_RECORDS_PER_REPLY};
use fog_core::seeking::field_record::{FieldRecord, RecordDefect, FIELD_RECORD_LEN};

/// Why the field log failed (records already in flash are unaffected).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FieldLogError {
    /// The region is not at least two whole erase sectors holding a slot each, or the
    /// flash word does not divide a record.
    Geometry,
    /// A flash read, erase or write failed.
    Flash,
    /// The record just written did not read back as written.
    Readback,
    /// The record's values are not finite / in range.
    Implausible,
    /// The sequence counter is exhausted.
    SequenceExhausted,
}

impl core::fmt::Display for FieldLogError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Geometry => "region is not >= 2 whole erase sectors of record slots",
            Self::Flash => "flash operation failed",
            Self::Readback => "written record did not read back",
            Self::Implausible => "record values not finite or out of range",
            Self::SequenceExhausted => "record sequence exhausted",
        })
    }
}

/// What `open` found (the boot line).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FieldLogScan {
    pub valid: u32,
    /// Slots neither erased nor a valid record (torn writes or erases).
    pub corrupt: u32,
    pub oldest_sequence: Option<u32>,
    pub newest_sequence: Option<u32>,
}

/// The ring on `flash[base .. base + len]`.
pub struct FieldLog<F> {
    flash: F,
    base: u32,
    sectors: u32,
    slots_per_sector: u32,
    /// Next slot to write (0-based over the whole ring).
    cursor: u32,
    next_sequence: u32,
    scan: FieldLogScan,
}

impl<F: NorFlash> FieldLog<F> {
    /// Opens the ring (the boot path): checks the geometry and scans every slot.
    pub fn open(flash: F, base: u32, len: u32) -> Result<Self, FieldLogError> {
        let erase = F::ERASE_SIZE as u32;
        let fits = (base as usize)
            .checked_add(len as usize)
            .is_some_and(|end| end <= flash.capacity());
        let slots_per_sector = erase / FIELD_RECORD_LEN as u32;
        if !fits
            || erase == 0
            || !base.is_multiple_of(erase)
            || !len.is_multiple_of(erase)
            || len / erase < 2
            || slots_per_sector == 0
            || !FIELD_RECORD_LEN.is_multiple_of(F::WRITE_SIZE)
            || !FIELD_RECORD_LEN.is_multiple_of(F::READ_SIZE)
        {
            return Err(FieldLogError::Geometry);
        }
        let mut log = Self {
            flash,
            base,
            sectors: len / erase,
            slots_per_sector,
            cursor: 0,
            next_sequence: 1,
            scan: FieldLogScan::default(),
        };
        log.rescan()?;
        Ok(log)
    }

    /// What the boot scan found.
    pub fn scan(&self) -> FieldLogScan {
        self.scan
    }

    /// Records the ring can hold for sure (all sectors but the one being refilled).
    pub fn guaranteed_capacity(&self) -> u32 {
        (self.sectors - 1) * self.slots_per_sector
    }

    /// Gives the flash back (tests "reboot" by reopening it).
    pub fn into_flash(self) -> F {
        self.flash
    }

    fn slots(&self) -> u32 {
        self.sectors * self.slots_per_sector
    }

    fn slot_addr(&self, slot: u32) -> u32 {
        let sector = slot / self.slots_per_sector;
        let within = slot % self.slots_per_sector;
        self.base + sector * F::ERASE_SIZE as u32 + within * FIELD_RECORD_LEN as u32
    }

    fn read_slot(&mut self, slot: u32) -> Result<Result<FieldRecord, RecordDefect>, FieldLogError> {
        let mut raw = [0u8; FIELD_RECORD_LEN];
        self.flash
            .read(self.slot_addr(slot), &mut raw)
            .map_err(|_| FieldLogError::Flash)?;
        Ok(FieldRecord::from_bytes(&raw))
    }

    /// Scans every slot: counts, the newest record, the cursor after it.
    fn rescan(&mut self) -> Result<(), FieldLogError> {
        let mut scan = FieldLogScan::default();
        let mut newest_slot = None;
        for slot in 0..self.slots() {
            match self.read_slot(slot)? {
                Ok(r) => {
                    scan.valid += 1;
                    if scan.newest_sequence.is_none_or(|n| r.sequence > n) {
                        scan.newest_sequence = Some(r.sequence);
                        newest_slot = Some(slot);
                    }
                    if scan.oldest_sequence.is_none_or(|o| r.sequence < o) {
                        scan.oldest_sequence = Some(r.sequence);
                    }
                }
                Err(RecordDefect::Corrupt) => scan.corrupt += 1,
                Err(RecordDefect::Empty) => {}
            }
        }
        self.scan = scan;
        self.next_sequence = match scan.newest_sequence {
            Some(n) => n.checked_add(1).ok_or(FieldLogError::SequenceExhausted)?,
            None => 1,
        };
        self.cursor = newest_slot.map_or(0, |s| (s + 1) % self.slots());
        Ok(())
    }

    /// `true` if every byte of the sector is erased.
    fn sector_erased(&mut self, sector: u32) -> Result<bool, FieldLogError> {
        let start = self.base + sector * F::ERASE_SIZE as u32;
        let mut piece = [0u8; 64];
        let mut at = 0;
        while at < F::ERASE_SIZE as u32 {
            let n = (F::ERASE_SIZE as u32 - at).min(piece.len() as u32) as usize;
            self.flash
                .read(start + at, &mut piece[..n])
                .map_err(|_| FieldLogError::Flash)?;
            if piece[..n].iter().any(|&b| b != 0xFF) {
                return Ok(false);
            }
            at += n as u32;
        }
        Ok(true)
    }

    fn erase_sector(&mut self, sector: u32) -> Result<(), FieldLogError> {
        let start = self.base + sector * F::ERASE_SIZE as u32;
        self.flash
            .erase(start, start + F::ERASE_SIZE as u32)
            .map_err(|_| FieldLogError::Flash)
    }

    /// Moves the cursor to a slot that can be written: a sector is erased when the
    /// cursor enters it (unless already erased), a non-erased slot inside the current
    /// sector (a torn write) is skipped.
    fn writable_slot(&mut self) -> Result<u32, FieldLogError> {
        for _ in 0..=self.slots() {
            let slot = self.cursor;
            if slot.is_multiple_of(self.slots_per_sector) {
                let sector = slot / self.slots_per_sector;
                if !self.sector_erased(sector)? {
                    self.erase_sector(sector)?;
                }
                return Ok(slot);
            }
            match self.read_slot(slot)? {
                Err(RecordDefect::Empty) => return Ok(slot),
                _ => self.cursor = (slot + 1) % self.slots(),
            }
        }
        Err(FieldLogError::Flash)
    }

    /// Appends `record` with the next sequence number (the record's own is replaced) and
    /// returns it as stored. On error nothing already stored is lost.
    pub fn append(&mut self, record: FieldRecord) -> Result<FieldRecord, FieldLogError> {
        let record = FieldRecord {
            sequence: self.next_sequence,
            ..record
        };
        if !record.is_plausible() {
            return Err(FieldLogError::Implausible);
        }
        let next = self
            .next_sequence
            .checked_add(1)
            .ok_or(FieldLogError::SequenceExhausted)?;
        let slot = self.writable_slot()?;
        let addr = self.slot_addr(slot);
        self.flash
            .write(addr, &record.to_bytes())
            .map_err(|_| FieldLogError::Flash)?;
        // The slot is used whatever the read-back says: never written twice.
        self.cursor = (slot + 1) % self.slots();
        match self.read_slot(slot)? {
            Ok(back) if back == record => {}
            _ => return Err(FieldLogError::Readback),
        }
        self.next_sequence = next;
        self.scan.valid += 1;
        self.scan.newest_sequence = Some(record.sequence);
        if self.scan.oldest_sequence.is_none() {
            self.scan.oldest_sequence = Some(record.sequence);
        }
        if slot.is_multiple_of(self.slots_per_sector) {
            // A sector was (re)filled from empty: the oldest kept record may have moved.
            self.refresh_oldest()?;
        }
        Ok(record)
    }

    fn refresh_oldest(&mut self) -> Result<(), FieldLogError> {
        let (mut oldest, mut valid) = (None, 0);
        for slot in 0..self.slots() {
            if let Ok(r) = self.read_slot(slot)? {
                valid += 1;
                if oldest.is_none_or(|o| r.sequence < o) {
                    oldest = Some(r.sequence);
                }
            }
        }
        self.scan.oldest_sequence = oldest;
        self.scan.valid = valid;
        Ok(())
    }

    /// Up to `max` (and `MAX_FIELD_RECORDS_PER_REPLY`) records with sequence >= `from`,
    /// oldest first, into `out`; returns how many.
    pub fn read_from(
        &mut self,
        from: u32,
        max: usize,
        out: &mut [FieldRecord; MAX_FIELD_RECORDS_PER_REPLY],
    ) -> Result<usize, FieldLogError> {
        let max = max.min(MAX_FIELD_RECORDS_PER_REPLY);
        let mut n = 0usize;
        for slot in 0..self.slots() {
            let Ok(r) = self.read_slot(slot)? else {
                continue;
            };
            if r.sequence < from {
                continue;
            }
            // Insertion into the sorted first `n` (n <= 4), dropping the largest if full.
            let Some(at) = out[..n]
                .iter()
                .position(|o| r.sequence < o.sequence)
                .or((n < max).then_some(n))
            else {
                continue;
            };
            let end = (n + 1).min(max);
            for k in (at + 1..end).rev() {
                out[k] = out[k - 1];
            }
            if at < max {
                out[at] = r;
            }
            n = end;
        }
        Ok(n)
    }

    /// The link answer to `GetFieldRecords { from_sequence, max_count }`.
    pub fn answer(&mut self, from_sequence: u32, max_count: u8) -> FieldRecordBatch {
        let mut records = [FieldRecord::ZERO; MAX_FIELD_RECORDS_PER_REPLY];
        let read = self.read_from(from_sequence, usize::from(max_count), &mut records);
        FieldRecordBatch {
            count: read.map_or(0, |n| n as u8),
            records,
            oldest_sequence: self.scan.oldest_sequence,
            newest_sequence: self.scan.newest_sequence,
            readable: read.is_ok(),
        }
    }
}
