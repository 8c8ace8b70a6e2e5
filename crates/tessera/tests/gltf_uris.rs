//! A `.gltf`'s buffer URIs are read within bounds: at most `byteLength` bytes, only regular
//! files, only inside the model's folder unless the caller allows more, and every error names
//! both the `.gltf` and the file its URI names. A global allocator records the largest single
//! allocation, so a read of a whole oversized file (today's bug: a 96-byte buffer in a 3 GB
//! file read 3 GB) fails the test instead of merely taking long.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use tessera::io::{self, glb::UriScope};
use tessera::surface::BuildOptions;
use tessera::Error;

/// Records the largest allocation (or reallocation) made.
struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only records sizes.
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        // SAFETY: the caller's contract is passed on as it is.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        // SAFETY: as above.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Largest = Largest;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tessera-uris-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

use tessera::fuzzing::{one_triangle_buffer as triangle_bin, one_triangle_gltf as gltf_with_uri};

fn load(path: &Path, uri_scope: UriScope) -> tessera::Result<tessera::surface::SurfaceSet> {
    io::load(path, io::LoadOptions { uri_scope, ..Default::default() })
}

#[test]
fn buffer_uris_are_bounded_confined_and_named() {
    let dir = scratch("hostile");
    let model = dir.join("model");
    std::fs::create_dir_all(model.join("sub")).unwrap();
    let outside = dir.join("outside.bin");
    std::fs::write(&outside, triangle_bin()).unwrap();
    std::fs::write(model.join("ok.bin"), triangle_bin()).unwrap();
    std::fs::write(model.join("short.bin"), &triangle_bin()[..20]).unwrap();
    // The buffer's 44 bytes followed by a sparse GiB: reading it whole would allocate 1 GiB.
    let big = std::fs::File::create(model.join("big.bin")).unwrap();
    std::io::Write::write_all(&mut &big, &triangle_bin()).unwrap();
    big.set_len(1 << 30).unwrap();
    drop(big);
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, model.join("link.bin")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", model.join("zero.bin")).unwrap();
    }

    let write = |name: &str, uri: &str| {
        let path = model.join(name);
        std::fs::write(&path, gltf_with_uri(uri)).unwrap();
        path
    };

    // A buffer inside the folder is read, and a big file only as far as its byteLength.
    LARGEST.store(0, Ordering::Relaxed);
    let set = load(&write("big.gltf", "big.bin"), UriScope::ModelFolder).unwrap();
    assert_eq!(set.patches.len(), 1);
    let largest = LARGEST.load(Ordering::Relaxed);
    assert!(largest < 64 << 20, "reading a 44-byte buffer allocated {largest} bytes at once");
    assert_eq!(load(&write("ok.gltf", "ok.bin"), UriScope::ModelFolder).unwrap().patches.len(), 1);

    // Refusals: (file, uri, scope, what the message must say besides both paths).
    let outside_uri = "..%2Foutside.bin";
    let mut cases: Vec<(&str, String, UriScope, &str, PathBuf)> = vec![
        (
            "up.gltf",
            outside_uri.to_string(),
            UriScope::ModelFolder,
            "outside the model's folder",
            outside.clone(),
        ),
        (
            "abs.gltf",
            outside.display().to_string(),
            UriScope::ModelFolder,
            "outside the model's folder",
            outside.clone(),
        ),
        (
            "passwd.gltf",
            "../../../../../../../../etc/passwd".into(),
            UriScope::ModelFolder,
            "outside",
            "/etc/passwd".into(),
        ),
        ("sub.gltf", "sub".into(), UriScope::Anywhere, "not a regular file", model.join("sub")),
        (
            "short.gltf",
            "short.bin".into(),
            UriScope::ModelFolder,
            "declares 44 bytes",
            model.join("short.bin"),
        ),
        (
            "missing.gltf",
            "missing.bin".into(),
            UriScope::ModelFolder,
            "cannot find it",
            model.join("missing.bin"),
        ),
        (
            "dev.gltf",
            "/dev/zero".into(),
            UriScope::ModelFolder,
            "outside the model's folder",
            "/dev/zero".into(),
        ),
        ("devany.gltf", "/dev/zero".into(), UriScope::Anywhere, "not a regular file", "/dev/zero".into()),
    ];
    #[cfg(unix)]
    {
        cases.push((
            "link.gltf",
            "link.bin".into(),
            UriScope::ModelFolder,
            "outside the model's folder",
            outside.clone(),
        ));
        cases.push((
            "zero.gltf",
            "zero.bin".into(),
            UriScope::Anywhere,
            "not a regular file",
            "/dev/zero".into(),
        ));
    }
    for (name, uri, scope, needle, named) in cases {
        let path = write(name, &uri);
        LARGEST.store(0, Ordering::Relaxed);
        let err = load(&path, scope).expect_err(name);
        let largest = LARGEST.load(Ordering::Relaxed);
        assert!(largest < 64 << 20, "{name}: allocated {largest} bytes at once before refusing");
        let message = err.to_string();
        assert!(message.contains(&path.display().to_string()), "{name}: {message} does not name the .gltf");
        let named = named.canonicalize().unwrap_or(named);
        assert!(
            message.contains(&named.display().to_string()),
            "{name}: {message} does not name {}",
            named.display()
        );
        assert!(message.contains(needle), "{name}: {message} lacks {needle:?}");
        assert!(
            matches!(err, Error::Unsupported { .. } | Error::Parse { .. } | Error::Referenced { .. }),
            "{name}: {err:?}"
        );
    }

    // The caller may allow a file outside the folder: the same buffer then reads.
    let up = write("up_allowed.gltf", outside_uri);
    assert_eq!(load(&up, UriScope::Anywhere).unwrap().patches.len(), 1);
    #[cfg(unix)]
    assert_eq!(load(&write("link_allowed.gltf", "link.bin"), UriScope::Anywhere).unwrap().patches.len(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn inputs_that_are_not_regular_files_are_refused_by_name() {
    let dir = scratch("kinds");
    let folder = dir.join("cages");
    std::fs::create_dir_all(&folder).unwrap();
    let err = io::load(&folder, BuildOptions::default()).unwrap_err();
    assert!(err.to_string().contains("is a folder"), "{err}");
    let folder_obj = dir.join("folder.obj");
    std::fs::create_dir_all(&folder_obj).unwrap();
    for err in
        [io::load(&folder_obj, BuildOptions::default()).unwrap_err(), io::read_mesh(&folder_obj).unwrap_err()]
    {
        assert!(err.to_string().contains("is a folder"), "{err}");
    }
    #[cfg(unix)]
    {
        let device = dir.join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &device).unwrap();
        LARGEST.store(0, Ordering::Relaxed);
        let err = io::load(&device, BuildOptions::default()).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
        assert!(LARGEST.load(Ordering::Relaxed) < 64 << 20);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
