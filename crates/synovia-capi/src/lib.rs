//! # synovia-capi
//!
//! The C ABI of synovia, for embedding the contact solver in other software (e.g. surgical
//! navigation). The header `include/synovia.h` is generated from this file by cbindgen
//! (`tests/header.rs` checks that it is up to date); `docs/c-api.md` is the user guide and
//! `examples/c/` a complete C program.
//!
//! A model ([`SynModel`]) is created from a TOML scenario file ([`syn_model_from_scenario`]) or
//! from arrays ([`syn_model_from_arrays`]), gets boundary conditions and contact pairs by
//! integer part tags, is solved statically ([`syn_model_solve_static`]) or by quasi-static
//! steps carrying the friction state ([`syn_model_solve_step`]), and its results are copied into
//! caller-owned buffers. Every function returns a [`SynStatus`]; the message of the last
//! failure on the calling thread is copied out by [`syn_last_error_message`]. No Rust panic
//! crosses the boundary: every entry point runs under `catch_unwind` and reports a panic as
//! [`SynStatus::Panic`].
//!
//! Handles are not pointers to Rust memory: they are keys into a registry of live models, so
//! a NULL, freed or made-up handle is reported as [`SynStatus::InvalidHandle`] (or
//! [`SynStatus::NullPointer`]) instead of being dereferenced.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use synovia::material::{isotropic, plane_strain, Material};
use synovia_scenario::arrays::{ConditionKind, ModelArrays};
use synovia_scenario::scenario::Scenario;

mod state;

use state::State;

/// Status code returned by every `syn_*` function that can fail (0 = success).
///
/// The message of the last failure on the calling thread is available through
/// `syn_last_error_message`.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SynStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument is NULL (or a non-empty array is NULL).
    NullPointer = 1,
    /// The model handle is not a live handle of this library (freed, never created, corrupted).
    InvalidHandle = 2,
    /// An argument has an invalid value (non-finite number, unknown part tag or name, unknown
    /// solver, contact kind, a time not after the last step, misaligned pointer, bad UTF-8).
    InvalidArgument = 3,
    /// An array length or count does not match (e.g. coordinates not a multiple of the
    /// dimension, one body id per element, buffer of the wrong size).
    SizeMismatch = 4,
    /// An index is out of range (node index of an element or facet, body id, pair index).
    IndexOutOfRange = 5,
    /// The scenario file cannot be read or is invalid (message: file:line:column, key).
    Scenario = 6,
    /// The model rejected the input (invalid mesh or material, facet not on the boundary,
    /// conflicting conditions on a part, missing boundary data, rigid body motion not
    /// restrained).
    ModelRejected = 7,
    /// The solver failed (no convergence, Coulomb fixed point not converging).
    SolveFailed = 8,
    /// Results were requested before a successful solve (or after the model changed).
    NoSolution = 9,
    /// An internal error (a Rust panic) was caught; the model it happened in should be freed.
    Panic = 10,
}

/// Kind of a body–body contact pair (the `kind` argument of `syn_model_add_contact`).
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SynContactKind {
    /// Node-to-node: the two parts have nodes at matching positions.
    NodeToNode = 0,
    /// Node-to-segment (2D) / node-to-facet (3D): any meshes; the first part's nodes (slave)
    /// are projected onto the second part's facets (master).
    NodeToSegment = 1,
}

/// An opaque model handle: created by `syn_model_from_scenario` or `syn_model_from_arrays`,
/// released by `syn_model_free`.
pub struct SynModel {
    _private: [u8; 0],
}

/// The arrays of a model built by `syn_model_from_arrays`. All indices are 0-based; every
/// array is read during the call only (the library keeps copies). `*_len` is the number of
/// elements of the array (not bytes); an array with length 0 may be NULL.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SynMeshArrays {
    /// 2 or 3.
    pub dimension: u32,
    /// Node coordinates, `n_nodes * dimension` values (x0, y0, [z0,] x1, …).
    pub coords: *const f64,
    /// Length of `coords`.
    pub coords_len: usize,
    /// P1 elements: `dimension + 1` node indices per element (triangles in 2D, tetrahedra in
    /// 3D), positively oriented.
    pub elements: *const i32,
    /// Length of `elements` (`n_elements * (dimension + 1)`).
    pub elements_len: usize,
    /// Body id of each element (0 .. n_bodies - 1); a node belongs to the elements of one body.
    pub element_body: *const i32,
    /// Length of `element_body` (must be `n_elements`).
    pub element_body_len: usize,
    /// Boundary facets: `dimension` node indices each (edges in 2D, triangles in 3D, any
    /// order); each must be a boundary facet of its body.
    pub facets: *const i32,
    /// Length of `facets` (`n_facets * dimension`).
    pub facets_len: usize,
    /// Tag of each facet: the facets with one tag form a part (all on one body); conditions
    /// and contact pairs refer to parts by tag.
    pub facet_tags: *const i32,
    /// Length of `facet_tags` (must be `n_facets`).
    pub facet_tags_len: usize,
    /// Young's modulus of each body (n_bodies values).
    pub young: *const f64,
    /// Length of `young` (= n_bodies).
    pub young_len: usize,
    /// Poisson's ratio of each body (plane strain in 2D).
    pub poisson: *const f64,
    /// Length of `poisson` (must be n_bodies).
    pub poisson_len: usize,
}

/// Figures of the last solve of a model (`syn_model_get_solve_info`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct SynSolveInfo {
    /// Time of the solution.
    pub time: f64,
    /// Step of the quasi-static sequence: 0 for `syn_model_solve_static`, +1 per
    /// `syn_model_solve_step`.
    pub step: usize,
    /// Contact solver iterations of the solve (including nested-iteration coarse levels and
    /// Coulomb fixed-point solves).
    pub iterations: usize,
    /// Largest relative KKT residual of the solution (equilibrium, penetration, negative
    /// pressure, complementarity, friction); 0 without contact.
    pub kkt_residual: f64,
    /// Reduced unknowns of the system.
    pub n_dofs: usize,
    /// Contact nodes of all pairs.
    pub n_contact_nodes: usize,
}

// ----- errors -----

/// A failure: status and message.
#[derive(Debug)]
pub(crate) struct Fail {
    status: SynStatus,
    message: String,
}

impl Fail {
    pub(crate) fn new(status: SynStatus, message: impl Into<String>) -> Self {
        Self { status, message: message.into() }
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_last_error(message: &str) {
    LAST_ERROR.with(|e| {
        if let Ok(mut e) = e.try_borrow_mut() {
            e.clear();
            e.push_str(message);
        }
    });
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    }
}

/// Runs an entry point: catches panics, records the message, returns the status.
fn guard(f: impl FnOnce() -> Result<(), Fail>) -> SynStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => {
            set_last_error("");
            SynStatus::Ok
        }
        Ok(Err(e)) => {
            set_last_error(&e.message);
            e.status
        }
        Err(payload) => {
            set_last_error(&format!("internal error (panic): {}", panic_message(payload.as_ref())));
            SynStatus::Panic
        }
    }
}

// ----- handles -----

/// A live model.
enum AnyModel {
    D2(State<2>),
    D3(State<3>),
}

type Shared = Arc<Mutex<AnyModel>>;

/// Live models by handle value.
static REGISTRY: Mutex<BTreeMap<usize, Shared>> = Mutex::new(BTreeMap::new());
/// Next handle value (never reused).
static NEXT_HANDLE: AtomicUsize = AtomicUsize::new(1);
/// Handle values are multiples of this (they look like aligned pointers).
const HANDLE_STRIDE: usize = 16;

fn registry() -> MutexGuard<'static, BTreeMap<usize, Shared>> {
    // nothing panics while the registry is locked; a poisoned lock still holds valid data
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

fn register(model: AnyModel) -> *mut SynModel {
    let key = NEXT_HANDLE.fetch_add(1, Ordering::Relaxed).wrapping_mul(HANDLE_STRIDE);
    registry().insert(key, Arc::new(Mutex::new(model)));
    std::ptr::without_provenance_mut(key)
}

fn lookup(handle: *const SynModel) -> Result<Shared, Fail> {
    if handle.is_null() {
        return Err(Fail::new(SynStatus::NullPointer, "the model handle is NULL"));
    }
    registry()
        .get(&handle.addr())
        .cloned()
        .ok_or_else(|| Fail::new(SynStatus::InvalidHandle, format!("{handle:p} is not a live model handle")))
}

/// Runs `f` on the model behind `handle` (locked for the duration of the call).
fn with_model<T>(
    handle: *const SynModel,
    f: impl FnOnce(&mut AnyModel) -> Result<T, Fail>,
) -> Result<T, Fail> {
    let shared = lookup(handle)?;
    let mut guard = shared.lock().map_err(|_| {
        Fail::new(SynStatus::Panic, "an earlier call on this model panicked; its state is undefined: free it")
    })?;
    f(&mut guard)
}

fn dimension(m: &AnyModel) -> u32 {
    match m {
        AnyModel::D2(_) => 2,
        AnyModel::D3(_) => 3,
    }
}

macro_rules! dispatch {
    ($model:expr, $s:ident => $body:expr) => {
        match $model {
            AnyModel::D2($s) => $body,
            AnyModel::D3($s) => $body,
        }
    };
}

// ----- pointer helpers (the only places that read or write C memory) -----

fn check_aligned<T>(ptr: *const T, what: &str) -> Result<(), Fail> {
    if ptr.is_aligned() {
        Ok(())
    } else {
        Err(Fail::new(SynStatus::InvalidArgument, format!("`{what}` is not aligned for its type")))
    }
}

/// A slice of `len` values at `ptr` (`ptr` may be NULL when `len` is 0).
///
/// # Safety
/// Unless NULL, `ptr` must point to `len` initialised values that stay valid and unmodified
/// for `'a` (the C caller's contract for input arrays: valid during the call).
unsafe fn input<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], Fail> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Fail::new(SynStatus::NullPointer, format!("`{what}` is NULL but its length is {len}")));
    }
    check_aligned(ptr, what)?;
    if len.checked_mul(size_of::<T>()).is_none_or(|b| b > isize::MAX as usize) {
        return Err(Fail::new(SynStatus::SizeMismatch, format!("`{what}`: length {len} is too large")));
    }
    // SAFETY: ptr is non-null and aligned (checked above), the byte size fits in isize
    // (checked above), and the caller guarantees `len` readable initialised values for 'a.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// A mutable slice of `len` values at `ptr`, or `None` for NULL.
///
/// # Safety
/// Unless NULL, `ptr` must point to `len` writable values of type `T`, valid for `'a` and not
/// accessed otherwise meanwhile (the C caller's contract for output buffers).
unsafe fn output<'a, T>(ptr: *mut T, len: usize, what: &str) -> Result<Option<&'a mut [T]>, Fail> {
    if ptr.is_null() {
        return Ok(None);
    }
    check_aligned(ptr, what)?;
    if len.checked_mul(size_of::<T>()).is_none_or(|b| b > isize::MAX as usize) {
        return Err(Fail::new(SynStatus::SizeMismatch, format!("`{what}`: length {len} is too large")));
    }
    // SAFETY: ptr is non-null and aligned (checked above), the byte size fits in isize, and
    // the caller guarantees `len` writable values (plain numbers: any bit pattern written by
    // C is a valid T) used by nobody else during the call.
    Ok(Some(unsafe { std::slice::from_raw_parts_mut(ptr, len) }))
}

/// Writes `value` to the out-parameter `ptr`.
///
/// # Safety
/// Unless NULL, `ptr` must be valid for writing one `T`.
unsafe fn write<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Fail> {
    if ptr.is_null() {
        return Err(Fail::new(SynStatus::NullPointer, format!("`{what}` is NULL")));
    }
    check_aligned(ptr, what)?;
    // SAFETY: non-null and aligned (checked above); the caller guarantees it is writable.
    unsafe { ptr.write(value) };
    Ok(())
}

/// A UTF-8 string from a NUL-terminated C string.
///
/// # Safety
/// Unless NULL, `ptr` must point to a NUL-terminated string valid for `'a`.
unsafe fn string<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Fail> {
    if ptr.is_null() {
        return Err(Fail::new(SynStatus::NullPointer, format!("`{what}` is NULL")));
    }
    // SAFETY: non-null; the caller guarantees a NUL-terminated string valid for 'a.
    let c = unsafe { CStr::from_ptr(ptr) };
    c.to_str().map_err(|_| Fail::new(SynStatus::InvalidArgument, format!("`{what}` is not valid UTF-8")))
}

// ----- library -----

/// The library version, e.g. `"0.1.0"` (a static NUL-terminated string; do not free).
#[no_mangle]
pub extern "C" fn syn_version() -> *const c_char {
    static VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");
    VERSION.as_ptr().cast()
}

/// The name of a status code, e.g. `"SYN_STATUS_NULL_POINTER"` (a static NUL-terminated
/// string; `"SYN_STATUS_UNKNOWN"` for codes not in `SynStatus`).
#[no_mangle]
pub extern "C" fn syn_status_name(status: i32) -> *const c_char {
    let name: &'static CStr = match status {
        0 => c"SYN_STATUS_OK",
        1 => c"SYN_STATUS_NULL_POINTER",
        2 => c"SYN_STATUS_INVALID_HANDLE",
        3 => c"SYN_STATUS_INVALID_ARGUMENT",
        4 => c"SYN_STATUS_SIZE_MISMATCH",
        5 => c"SYN_STATUS_INDEX_OUT_OF_RANGE",
        6 => c"SYN_STATUS_SCENARIO",
        7 => c"SYN_STATUS_MODEL_REJECTED",
        8 => c"SYN_STATUS_SOLVE_FAILED",
        9 => c"SYN_STATUS_NO_SOLUTION",
        10 => c"SYN_STATUS_PANIC",
        _ => c"SYN_STATUS_UNKNOWN",
    };
    name.as_ptr()
}

/// Copies the message of the last call on the calling thread into `buf`.
///
/// The message is thread-local: every `syn_*` function that returns a `SynStatus` replaces it
/// (with `""` when it succeeds). At most `len - 1` bytes are copied, followed by a NUL byte;
/// with `buf == NULL` or `len == 0` nothing is written. Returns the length of the whole
/// message in bytes (without the NUL), so a return value `>= len` means it was truncated
/// (as `snprintf`). The message is UTF-8; truncation does not split a character.
///
/// # Safety
/// Unless NULL, `buf` must be valid for writing `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn syn_last_error_message(buf: *mut c_char, len: usize) -> usize {
    let copy = || {
        LAST_ERROR.with(|e| {
            let Ok(msg) = e.try_borrow() else { return 0 };
            if !buf.is_null() && len > 0 {
                let mut n = msg.len().min(len - 1);
                while !msg.is_char_boundary(n) {
                    n -= 1;
                }
                // SAFETY: buf is non-null and the caller guarantees `len` writable bytes;
                // n + 1 <= len bytes are written; source and destination cannot overlap
                // (the message is owned by this library).
                unsafe {
                    std::ptr::copy_nonoverlapping(msg.as_ptr().cast::<c_char>(), buf, n);
                    buf.add(n).write(0);
                }
            }
            msg.len()
        })
    };
    catch_unwind(AssertUnwindSafe(copy)).unwrap_or(0)
}

// ----- creating and freeing models -----

/// Creates a model from a TOML scenario file (the format of the `synovia` command,
/// `docs/scenario.md`): its bodies, parts, boundary conditions with load histories, contact
/// pairs and solver. The scenario's `[analysis]` is not run: solve with
/// `syn_model_solve_static` / `syn_model_solve_step`; its solver options (nested iteration,
/// ordering, quasi-static options) are used.
///
/// Nodes are numbered body by body in file order (the nodes of body 0, then of body 1, …).
/// Parts are tagged 0, 1, … body by body in the order of the body's parts; look a tag up with
/// `syn_model_part_tag`. Pairs of the scenario come first, in file order.
///
/// On success `*out` receives a new handle owned by the caller (release it with
/// `syn_model_free`); on failure `*out` is set to NULL (if `out` is not NULL).
///
/// # Safety
/// `path` must be a NUL-terminated string; `out` must be valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn syn_model_from_scenario(path: *const c_char, out: *mut *mut SynModel) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract: path is NULL or a NUL-terminated string.
        let path = unsafe { string(path, "path") }?;
        let sc = Scenario::from_file(path).map_err(|e| Fail::new(SynStatus::Scenario, e.to_string()))?;
        let model = match sc.doc.dimension.get_ref() {
            2 => AnyModel::D2(State::<2>::from_scenario(&sc)?),
            3 => AnyModel::D3(State::<3>::from_scenario(&sc)?),
            d => {
                return Err(Fail::new(
                    SynStatus::Scenario,
                    format!("{path}: dimension must be 2 or 3, got {d}"),
                ))
            }
        };
        let handle = register(model);
        // SAFETY: as above (out was checked non-null and aligned by the first write).
        unsafe { write(out, handle, "out") }
    })
}

/// Creates a model from arrays (see `SynMeshArrays`): bodies made of P1 elements with an
/// isotropic linear elastic material each (plane strain in 2D), boundary parts from tagged
/// facets. Bodies are named `body_0`, `body_1`, …, parts `tag_<tag>` (for
/// `syn_model_part_tag`). Nodes keep the numbering of `coords`; a node used by no element
/// gets zero displacement.
///
/// Errors: `SYN_STATUS_NULL_POINTER` (NULL `arrays`/`out`, NULL non-empty array),
/// `SYN_STATUS_SIZE_MISMATCH` (lengths not multiples of the dimension / cell size, counts that
/// disagree), `SYN_STATUS_INDEX_OUT_OF_RANGE` (node index or body id out of range),
/// `SYN_STATUS_INVALID_ARGUMENT` (dimension, non-finite coordinates, a node in two bodies, a
/// tag on two bodies, a body without elements), `SYN_STATUS_MODEL_REJECTED` (inverted or
/// degenerate elements, facets that are not boundary facets, invalid E or ν).
///
/// On success `*out` receives a new handle owned by the caller (release it with
/// `syn_model_free`); on failure `*out` is set to NULL (if `out` is not NULL).
///
/// # Safety
/// `arrays` must point to a `SynMeshArrays` whose pointers are NULL or valid for reading their
/// `*_len` values during the call; `out` must be valid for writing a pointer.
#[no_mangle]
pub unsafe extern "C" fn syn_model_from_arrays(
    arrays: *const SynMeshArrays,
    out: *mut *mut SynModel,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, std::ptr::null_mut(), "out") }?;
        if arrays.is_null() {
            return Err(Fail::new(SynStatus::NullPointer, "`arrays` is NULL"));
        }
        check_aligned(arrays, "arrays")?;
        // SAFETY: non-null and aligned (checked above); the caller guarantees it points to a
        // SynMeshArrays (plain old data: any field values are valid to read).
        let a = unsafe { arrays.read() };
        // SAFETY: for all seven arrays, the caller guarantees each pointer is NULL or valid for its
        // `*_len` values during this call; the slices do not outlive it.
        let arr = unsafe {
            ModelArrays {
                coords: input(a.coords, a.coords_len, "coords")?,
                elements: input(a.elements, a.elements_len, "elements")?,
                element_body: input(a.element_body, a.element_body_len, "element_body")?,
                facets: input(a.facets, a.facets_len, "facets")?,
                facet_tags: input(a.facet_tags, a.facet_tags_len, "facet_tags")?,
                young: input(a.young, a.young_len, "young")?,
                poisson: input(a.poisson, a.poisson_len, "poisson")?,
            }
        };
        let model = match a.dimension {
            2 => AnyModel::D2(State::<2>::from_arrays(&arr, |e, nu| {
                Ok(Arc::new(plane_strain(e, nu)?) as Arc<dyn Material<2>>)
            })?),
            3 => AnyModel::D3(State::<3>::from_arrays(&arr, |e, nu| {
                Ok(Arc::new(isotropic(e, nu)?) as Arc<dyn Material<3>>)
            })?),
            d => {
                return Err(Fail::new(
                    SynStatus::InvalidArgument,
                    format!("dimension must be 2 or 3, got {d}"),
                ))
            }
        };
        let handle = register(model);
        // SAFETY: as above.
        unsafe { write(out, handle, "out") }
    })
}

/// Releases a model and everything it owns. `syn_model_free(NULL)` does nothing and returns
/// `SYN_STATUS_OK`; a handle that is not live (already freed, made up) gives
/// `SYN_STATUS_INVALID_HANDLE` and changes nothing. The handle must not be used afterwards.
#[no_mangle]
pub extern "C" fn syn_model_free(model: *mut SynModel) -> SynStatus {
    guard(|| {
        if model.is_null() {
            return Ok(());
        }
        match registry().remove(&model.addr()) {
            Some(_) => Ok(()),
            None => Err(Fail::new(SynStatus::InvalidHandle, format!("{model:p} is not a live model handle"))),
        }
    })
}

// ----- queries -----

/// Writes the dimension (2 or 3) of the model to `*out`.
///
/// # Safety
/// `out` must be valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_dimension(model: *const SynModel, out: *mut u32) -> SynStatus {
    guard(|| {
        let d = with_model(model, |m| Ok(dimension(m)))?;
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, d, "out") }
    })
}

/// Writes the number of nodes (of the global numbering) to `*out`.
///
/// # Safety
/// `out` must be valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_num_nodes(model: *const SynModel, out: *mut usize) -> SynStatus {
    guard(|| {
        let n = with_model(model, |m| Ok(dispatch!(m, s => s.n_nodes())))?;
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, n, "out") }
    })
}

/// Writes the number of contact pairs to `*out`.
///
/// # Safety
/// `out` must be valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_num_pairs(model: *const SynModel, out: *mut usize) -> SynStatus {
    guard(|| {
        let n = with_model(model, |m| Ok(dispatch!(m, s => s.n_pairs())))?;
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, n, "out") }
    })
}

/// Looks up the tag of part `part` of body `body` (names as in the scenario file, or
/// `body_<b>` / `tag_<t>` for models from arrays) and writes it to `*tag`.
///
/// # Safety
/// `body` and `part` must be NUL-terminated strings; `tag` must be valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_part_tag(
    model: *const SynModel,
    body: *const c_char,
    part: *const c_char,
    tag: *mut i32,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: NULL or NUL-terminated strings.
        let (body, part) = unsafe { (string(body, "body")?, string(part, "part")?) };
        let t = with_model(model, |m| dispatch!(m, s => s.part_tag(body, part)))?;
        // SAFETY: the caller's contract: tag is NULL or writable.
        unsafe { write(tag, t, "tag") }
    })
}

// ----- conditions and pairs -----

/// Clamps the part `tag` (`u = 0`). The part must have no condition yet (a second call on a
/// clamped part is a no-op).
#[no_mangle]
pub extern "C" fn syn_model_clamp(model: *mut SynModel, tag: i32) -> SynStatus {
    guard(|| with_model(model, |m| dispatch!(m, s => s.set_condition(tag, ConditionKind::Clamped, &[]))))
}

fn set_values(model: *mut SynModel, tag: i32, kind: ConditionKind, v: &[f64]) -> Result<(), Fail> {
    with_model(model, |m| dispatch!(m, s => s.set_condition(tag, kind, v)))
}

/// Prescribes the displacement `value` (`len` = dimension components) on part `tag`. The first
/// call makes the part a prescribed-displacement part; later calls change the value, which
/// takes effect at the next solve (no refactorisation). Fails with
/// `SYN_STATUS_MODEL_REJECTED` if the part already has another condition or is a contact part.
///
/// # Safety
/// `value` must be NULL or valid for reading `len` doubles.
#[no_mangle]
pub unsafe extern "C" fn syn_model_set_displacement(
    model: *mut SynModel,
    tag: i32,
    value: *const f64,
    len: usize,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: value is NULL or has len readable doubles.
        let v = unsafe { input(value, len, "value") }?;
        if value.is_null() {
            return Err(Fail::new(SynStatus::NullPointer, "`value` is NULL"));
        }
        set_values(model, tag, ConditionKind::Displacement, v)
    })
}

/// Prescribes the traction `value` (force per unit area, `len` = dimension components) on part
/// `tag`. First call: makes it a traction part; later calls change the value.
///
/// # Safety
/// `value` must be NULL or valid for reading `len` doubles.
#[no_mangle]
pub unsafe extern "C" fn syn_model_set_traction(
    model: *mut SynModel,
    tag: i32,
    value: *const f64,
    len: usize,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: value is NULL or has len readable doubles.
        let v = unsafe { input(value, len, "value") }?;
        if value.is_null() {
            return Err(Fail::new(SynStatus::NullPointer, "`value` is NULL"));
        }
        set_values(model, tag, ConditionKind::Traction, v)
    })
}

/// Prescribes a normal pressure `p` on part `tag` (`p > 0` pushes into the body). First call:
/// makes it a traction part; later calls change the value.
#[no_mangle]
pub extern "C" fn syn_model_set_pressure(model: *mut SynModel, tag: i32, p: f64) -> SynStatus {
    guard(|| set_values(model, tag, ConditionKind::Pressure, &[p]))
}

/// Adds a body–body contact pair between part `slave_tag` (body k) and part `master_tag`
/// (body l) of kind `kind` (a `SynContactKind` value) with Coulomb coefficient `friction`
/// (0: frictionless). Writes the pair's index (0-based, in order of creation) to `*pair`
/// unless `pair` is NULL. Both parts must be free of conditions.
///
/// # Safety
/// `pair` must be NULL or valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_add_contact(
    model: *mut SynModel,
    slave_tag: i32,
    master_tag: i32,
    kind: i32,
    friction: f64,
    pair: *mut usize,
) -> SynStatus {
    guard(|| {
        let segment = match kind {
            0 => false,
            1 => true,
            k => return Err(Fail::new(SynStatus::InvalidArgument, format!("unknown contact kind {k}"))),
        };
        let i = with_model(
            model,
            |m| dispatch!(m, s => s.add_contact(slave_tag, master_tag, segment, friction)),
        )?;
        if pair.is_null() {
            return Ok(());
        }
        // SAFETY: the caller's contract: pair is NULL (handled) or writable.
        unsafe { write(pair, i, "pair") }
    })
}

/// Adds a contact pair between part `tag` and the rigid plane through `point` with normal
/// `normal` (pointing out of the obstacle, towards the body; both `len` = dimension values),
/// with Coulomb coefficient `friction`. Writes the pair's index to `*pair` unless NULL.
///
/// # Safety
/// `point` and `normal` must be valid for reading `len` doubles; `pair` NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn syn_model_add_contact_plane(
    model: *mut SynModel,
    tag: i32,
    point: *const f64,
    normal: *const f64,
    len: usize,
    friction: f64,
    pair: *mut usize,
) -> SynStatus {
    guard(|| {
        if point.is_null() || normal.is_null() {
            return Err(Fail::new(SynStatus::NullPointer, "`point` or `normal` is NULL"));
        }
        // SAFETY: the caller's contract: point and normal have len readable doubles.
        let (p, n) = unsafe { (input(point, len, "point")?, input(normal, len, "normal")?) };
        let i = with_model(model, |m| dispatch!(m, s => s.add_contact_plane(tag, p, n, friction)))?;
        if pair.is_null() {
            return Ok(());
        }
        // SAFETY: the caller's contract: pair is NULL (handled) or writable.
        unsafe { write(pair, i, "pair") }
    })
}

/// Sets the material law of body `body` (its id in `element_body`, or its position in the
/// scenario file) by name, with its constants:
///
/// | `law` | constants (`n_constants`) |
/// |---|---|
/// | `"isotropic"` | `E`, `ν` (2) — linear, plane strain in 2D |
/// | `"neo_hookean"` | `E`, `ν` (2) — compressible neo-Hookean, `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²` |
/// | `"mooney_rivlin"` | `c₁`, `c₂`, `λ` (3) — compressible Mooney–Rivlin |
///
/// A model with a hyperelastic law is solved by the Newton iteration with load stepping and
/// cut-back (docs/model.md §2.3; small strain unless `syn_model_set_kinematics` asks for
/// finite strain). The factorisation and the last solution are discarded.
///
/// Errors: `SYN_STATUS_NULL_POINTER` (NULL `law`, or NULL `constants` with `n_constants > 0`),
/// `SYN_STATUS_INDEX_OUT_OF_RANGE` (body), `SYN_STATUS_INVALID_ARGUMENT` (unknown law, wrong
/// number of constants, non-finite constants), `SYN_STATUS_MODEL_REJECTED` (inadmissible
/// constants, e.g. `E <= 0` or `ν` outside `(−1, ½)`).
///
/// # Safety
/// `law` must be NULL or NUL-terminated; `constants` NULL or valid for reading `n_constants`
/// doubles.
#[no_mangle]
pub unsafe extern "C" fn syn_model_set_material(
    model: *mut SynModel,
    body: usize,
    law: *const c_char,
    constants: *const f64,
    n_constants: usize,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: law is NULL or NUL-terminated.
        let law = unsafe { string(law, "law") }?;
        // SAFETY: the caller's contract: constants has n_constants readable doubles.
        let c = unsafe { input(constants, n_constants, "constants") }?;
        with_model(model, |m| dispatch!(m, s => s.set_material(body, law, c)))
    })
}

/// Sets the strain kinematics of body `body`: `"small"` (default) or `"finite"` (total
/// Lagrangian, the contact geometry rebuilt on the deformed configuration; solved by the
/// Newton iteration). The factorisation and the last solution are discarded.
///
/// Errors: `SYN_STATUS_NULL_POINTER`, `SYN_STATUS_INDEX_OUT_OF_RANGE` (body),
/// `SYN_STATUS_INVALID_ARGUMENT` (another name).
///
/// # Safety
/// `kinematics` must be NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn syn_model_set_kinematics(
    model: *mut SynModel,
    body: usize,
    kinematics: *const c_char,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: kinematics is NULL or NUL-terminated.
        let k = unsafe { string(kinematics, "kinematics") }?;
        with_model(model, |m| dispatch!(m, s => s.set_kinematics(body, k)))
    })
}

/// Chooses the contact solver by name: `"pdas-fallback"` (default), `"pdas"`, `"au-pdas"`,
/// `"uzawa-mprgp"`, `"dual-mprgp"`.
///
/// # Safety
/// `name` must be a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn syn_model_set_solver(model: *mut SynModel, name: *const c_char) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: name is NULL or NUL-terminated.
        let name = unsafe { string(name, "name") }?;
        with_model(model, |m| dispatch!(m, s => s.set_solver(name)))
    })
}

// ----- solving -----

/// Solves the static contact problem at time `t` (loads and prescribed displacements at `t`;
/// the initial state of the quasi-static scheme: frictionless unless the scenario sets
/// `initial_friction`). Starts a new quasi-static sequence. The first solve (and the first after
/// a condition or pair was added) assembles and factorises the system; later solves reuse it.
/// On failure the previous solution is kept.
#[no_mangle]
pub extern "C" fn syn_model_solve_static(model: *mut SynModel, t: f64) -> SynStatus {
    guard(|| with_model(model, |m| dispatch!(m, s => s.solve_static(t))))
}

/// One quasi-static step to time `t` (> the time of the last solution) with Coulomb friction:
/// the slip bound from the last solution's contact pressures and slip measured from its
/// displacements (Tresca per step, or the Coulomb fixed point when the scenario asks for it).
/// Without a previous solution it solves the static problem at `t`. Condition values set
/// since the last solve apply. On failure the previous solution is kept.
#[no_mangle]
pub extern "C" fn syn_model_solve_step(model: *mut SynModel, t: f64) -> SynStatus {
    guard(|| with_model(model, |m| dispatch!(m, s => s.solve_step(t))))
}

// ----- results -----

/// Copies the nodal displacements of the last solution into `out` (`len` must be
/// `n_nodes * dimension`, node-major: u_x0, u_y0, [u_z0,] u_x1, …).
///
/// # Safety
/// `out` must be valid for writing `len` doubles.
#[no_mangle]
pub unsafe extern "C" fn syn_model_get_displacements(
    model: *const SynModel,
    out: *mut f64,
    len: usize,
) -> SynStatus {
    guard(|| {
        // SAFETY: the caller's contract: out is NULL or has len writable doubles.
        let buf = unsafe { output(out, len, "out") }?
            .ok_or_else(|| Fail::new(SynStatus::NullPointer, "`out` is NULL"))?;
        with_model(model, |m| dispatch!(m, s => s.displacements(buf)))
    })
}

/// Writes the number of contact nodes of the last solution (all pairs) to `*out`.
///
/// # Safety
/// `out` must be valid for writing.
#[no_mangle]
pub unsafe extern "C" fn syn_model_num_contact_nodes(model: *const SynModel, out: *mut usize) -> SynStatus {
    guard(|| {
        let n = with_model(model, |m| dispatch!(m, s => s.n_contact_nodes()))?;
        // SAFETY: the caller's contract: out is NULL or writable.
        unsafe { write(out, n, "out") }
    })
}

/// Copies the contact nodes of the last solution, `n` of them (`n` must equal
/// `syn_model_num_contact_nodes`): the pair index of each (`pair`, n values), its node id in
/// the global numbering (`node`, n values; the slave-side node for body–body pairs), its
/// reference coordinates (`coords`, `n * dimension` values) and its contact pressure
/// (`pressure`, n values; the normal multiplier, ≥ 0). Any of the four buffers may be NULL to
/// skip it.
///
/// # Safety
/// Each non-NULL buffer must be valid for writing its number of values.
#[no_mangle]
pub unsafe extern "C" fn syn_model_get_contact_nodes(
    model: *const SynModel,
    n: usize,
    pair: *mut i32,
    node: *mut i32,
    coords: *mut f64,
    pressure: *mut f64,
) -> SynStatus {
    guard(|| {
        with_model(model, |m| {
            let d = dimension(m) as usize;
            let nd = n.checked_mul(d).ok_or_else(|| Fail::new(SynStatus::SizeMismatch, "n is too large"))?;
            // SAFETY: the caller's contract: each buffer is NULL or writable for its length
            // (n, n, n * dimension, n values); they are distinct buffers.
            let (p, nodes, c, pr) = unsafe {
                (
                    output(pair, n, "pair")?,
                    output(node, n, "node")?,
                    output(coords, nd, "coords")?,
                    output(pressure, n, "pressure")?,
                )
            };
            dispatch!(m, s => s.contact_nodes(n, p, nodes, c, pr))
        })
    })
}

/// Writes the total normal contact force of pair `pair` (`Σ κ_r λ_n,r`; per unit thickness in
/// 2D) to `*normal_force` and, unless `force` is NULL, the resultant contact force on the
/// pair's first body (normal and friction parts, 3 components, z = 0 in 2D) to `force[0..3]`.
///
/// # Safety
/// `normal_force` must be valid for writing; `force` NULL or valid for writing 3 doubles.
#[no_mangle]
pub unsafe extern "C" fn syn_model_get_pair_force(
    model: *const SynModel,
    pair: usize,
    normal_force: *mut f64,
    force: *mut f64,
) -> SynStatus {
    guard(|| {
        let (nf, f) = with_model(model, |m| dispatch!(m, s => s.pair_force(pair)))?;
        // SAFETY: the caller's contract: normal_force is NULL or writable.
        unsafe { write(normal_force, nf, "normal_force") }?;
        // SAFETY: the caller's contract: force is NULL or has 3 writable doubles.
        if let Some(buf) = unsafe { output(force, 3, "force") }? {
            buf.copy_from_slice(&f);
        }
        Ok(())
    })
}

/// Copies the figures of the last solve (time, step, iterations, KKT residual, …) to `*info`.
///
/// # Safety
/// `info` must be valid for writing a `SynSolveInfo`.
#[no_mangle]
pub unsafe extern "C" fn syn_model_get_solve_info(
    model: *const SynModel,
    info: *mut SynSolveInfo,
) -> SynStatus {
    guard(|| {
        let i = with_model(model, |m| dispatch!(m, s => s.info()))?;
        let out = SynSolveInfo {
            time: i.time,
            step: i.step,
            iterations: i.iterations,
            kkt_residual: i.kkt,
            n_dofs: i.n_dofs,
            n_contact_nodes: i.contact_nodes,
        };
        // SAFETY: the caller's contract: info is NULL or writable.
        unsafe { write(info, out, "info") }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_status_codes_with_a_message() {
        let status = guard(|| panic!("boom {}", 42));
        assert_eq!(status, SynStatus::Panic);
        let mut buf = [0 as c_char; 64];
        // SAFETY: buf has 64 writable bytes.
        let n = unsafe { syn_last_error_message(buf.as_mut_ptr(), buf.len()) };
        // SAFETY: syn_last_error_message NUL-terminates within buf.
        let msg = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_string_lossy().into_owned();
        assert_eq!(n, msg.len());
        assert!(msg.contains("panic") && msg.contains("boom 42"), "{msg}");
        // a success clears the message
        assert_eq!(guard(|| Ok(())), SynStatus::Ok);
        // SAFETY: NULL buffer: only the length is returned.
        assert_eq!(unsafe { syn_last_error_message(std::ptr::null_mut(), 0) }, 0);
    }

    #[test]
    fn a_panic_while_a_model_is_locked_poisons_only_that_model() {
        let coords = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0];
        let elements = [0, 1, 2];
        let body = [0];
        let (young, nu) = ([1.0], [0.3]);
        let arrays = SynMeshArrays {
            dimension: 2,
            coords: coords.as_ptr(),
            coords_len: 6,
            elements: elements.as_ptr(),
            elements_len: 3,
            element_body: body.as_ptr(),
            element_body_len: 1,
            facets: std::ptr::null(),
            facets_len: 0,
            facet_tags: std::ptr::null(),
            facet_tags_len: 0,
            young: young.as_ptr(),
            young_len: 1,
            poisson: nu.as_ptr(),
            poisson_len: 1,
        };
        let mut m = std::ptr::null_mut();
        // SAFETY: arrays and m are valid.
        assert_eq!(unsafe { syn_model_from_arrays(&arrays, &mut m) }, SynStatus::Ok);
        let status = guard(|| with_model(m, |_| -> Result<(), Fail> { panic!("inside") }));
        assert_eq!(status, SynStatus::Panic);
        let mut n = 0;
        // SAFETY: n is writable.
        assert_eq!(unsafe { syn_model_num_nodes(m, &mut n) }, SynStatus::Panic);
        assert_eq!(syn_model_free(m), SynStatus::Ok);
        assert_eq!(syn_model_free(m), SynStatus::InvalidHandle);
    }
}
