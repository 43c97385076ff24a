//! The write-through flash behind the QEMU build's persistent model store
//! (`fog_firmware::store::mirrored`): after every commit the backing image equals the
//! flash; a device rebooted from the image alone finds the same model; a backing that
//! fails at any write leaves an image that boots to a complete model (the old one) and
//! makes the store keep its slot; an image of the wrong size is refused whole.

use crate::upload_support;

use embedded_storage::nor_flash::NorFlash;
use fog_core::model::format::MAX_ENCODED_LEN;
use fog_firmware::store::mirrored::{
    load_image, Backing, BackingFailed, ImageError, MirroredFlash,
};
use fog_firmware::store::ram_flash::RamNorFlash;
use fog_firmware::store::{store_len, ModelStore};
use upload_support::{encode, sample_model, sign_with_test_key};

type Flash = RamNorFlash<{ store_len(256) }, 4, 256>;

/// An image in memory that fails every write after `writes_left` more.
struct VecImage {
    bytes: Vec<u8>,
    writes_left: Option<u32>,
}

impl VecImage {
    fn erased() -> Self {
        Self {
            bytes: vec![0xFF; store_len(256)],
            writes_left: None,
        }
    }
}

impl Backing for VecImage {
    fn write_at(&mut self, offset: u32, bytes: &[u8]) -> Result<(), BackingFailed> {
        if let Some(left) = self.writes_left.as_mut() {
            if *left == 0 {
                return Err(BackingFailed);
            }
            *left -= 1;
        }
        let at = offset as usize;
        self.bytes[at..at + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }
}

/// A new device's flash programmed from `image` (what the QEMU build does at boot).
fn flash_from(image: &[u8]) -> Result<Flash, ImageError> {
    let mut flash = Flash::new();
    let mut rest = image;
    load_image(&mut flash, |buf| {
        let n = buf.len().min(rest.len());
        buf[..n].copy_from_slice(&rest[..n]);
        rest = &rest[n..];
        Ok(n)
    })?;
    Ok(flash)
}

/// (sequence, model bytes) of the active model after booting from `image`.
fn boot_from(image: &[u8]) -> Option<(u32, Vec<u8>)> {
    let mut store = ModelStore::open(flash_from(image).expect("image loads"), 0).unwrap();
    let active = store.active().copied()?;
    let mut buf = vec![0u8; MAX_ENCODED_LEN];
    let bytes = store.read_active(&mut buf).unwrap().unwrap().to_vec();
    Some((active.header.sequence, bytes))
}

fn commit<F: NorFlash>(store: &mut ModelStore<F>, model: &[u8], counter: u32) -> bool {
    store
        .commit(model, &sign_with_test_key(counter, model), counter)
        .is_ok()
}

#[test]
fn image_equals_flash_after_each_commit_and_boots_to_the_same_model() {
    let mirrored = MirroredFlash::new(Flash::new(), Some(VecImage::erased()));
    let mut store = ModelStore::open(mirrored, 0).unwrap();
    let models: Vec<Vec<u8>> = (0..3)
        .map(|i| encode(&sample_model("FOG-A17", 20 + 10 * i, 1.0)))
        .collect();
    for (i, m) in models.iter().enumerate() {
        assert!(commit(&mut store, m, i as u32 + 1));
        let (flash, image) = store.into_flash().into_parts();
        let image = image.unwrap();
        assert_eq!(image.bytes, flash.contents(), "image after commit {i}");
        assert_eq!(boot_from(&image.bytes), Some((i as u32 + 1, m.clone())));
        store = ModelStore::open(MirroredFlash::new(flash, Some(image)), 0).unwrap();
    }
}

#[test]
fn a_backing_failure_at_any_write_leaves_an_image_with_the_old_model() {
    let old = encode(&sample_model("FOG-A17", 35, 1.0));
    let new = encode(&sample_model("FOG-A17", 50, 0.5));
    // Backing writes of one commit, counted on a backing that never fails.
    let count_writes = |fail_after: Option<u32>| {
        let mut image = VecImage::erased();
        let mut flash = Flash::new();
        {
            let mut s = ModelStore::open(&mut flash, 0).unwrap();
            assert!(commit(&mut s, &old, 1));
        }
        image.bytes.copy_from_slice(flash.contents());
        image.writes_left = fail_after;
        let mut store = ModelStore::open(MirroredFlash::new(flash, Some(image)), 0).unwrap();
        let ok = commit(&mut store, &new, 2);
        let still_old = store.active().map(|a| a.header.sequence) == Some(1);
        let (_, image) = store.into_flash().into_parts();
        (ok, still_old, image.unwrap().bytes)
    };
    let (ok, _, image) = count_writes(None);
    assert!(ok);
    assert_eq!(boot_from(&image), Some((2, new.clone())));
    let mut failures = 0;
    for k in 0.. {
        let (ok, still_old, image) = count_writes(Some(k));
        if ok {
            break;
        }
        failures += 1;
        assert!(still_old, "failure at write {k}: the store keeps its slot");
        assert_eq!(boot_from(&image), Some((1, old.clone())), "write {k}");
    }
    assert!(
        failures >= 4,
        "erase, body, header and marker each fail once"
    );
}

#[test]
fn an_image_of_the_wrong_size_is_refused_and_the_flash_left_erased() {
    let full = store_len(256);
    for len in [0, 1, 255, full - 4, full - 1, full + 1, full + 256] {
        let image = vec![0x5Au8; len];
        match flash_from(&image) {
            Err(ImageError::Size { found, expected }) => {
                assert_eq!(expected, full);
                assert!(
                    found == len || (len > full && found > full),
                    "{len}: {found}"
                );
            }
            other => panic!("{len}-byte image: {:?}", other.map(|_| ())),
        }
    }
    let mut flash = Flash::new();
    let err = load_image(&mut flash, |buf| {
        buf.fill(0);
        Ok(buf.len().min(100))
    });
    assert!(matches!(err, Err(ImageError::Size { .. })), "{err:?}");
    assert!(flash.contents().iter().all(|&b| b == 0xFF), "left erased");
    assert!(flash_from(&vec![0x5A; full]).is_ok());
}
