/* A linear RGB(A) framebuffer as the bytes of a scanline OpenEXR file, through OpenEXR's
   C core library: the library lays out the header, converts the floats to halves (or
   keeps them as floats), compresses each chunk of lines (ZIP) and writes the offset
   table; the bytes go to memory, so that the caller writes the file atomically and
   digests exactly what it wrote. */

#include <stdlib.h>
#include <string.h>
#include <stdint.h>
#include <openexr.h>

#include <caml/mlvalues.h>
#include <caml/memory.h>
#include <caml/alloc.h>
#include <caml/fail.h>
#include <caml/threads.h>

/* The file's bytes as the library writes them, at any offset. */
typedef struct {
  unsigned char *data;
  size_t len;   /* bytes written: the highest offset reached */
  size_t cap;
  int failed;   /* out of memory */
  char message[256];
} sink;

static int64_t sink_write(exr_const_context_t ctxt, void *userdata, const void *buffer,
                          uint64_t sz, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
  sink *s = (sink *)userdata;
  (void)ctxt;
  (void)error_cb;
  size_t end = (size_t)offset + (size_t)sz;
  if (end > s->cap) {
    size_t cap = s->cap ? s->cap : 65536;
    while (cap < end) cap *= 2;
    unsigned char *d = realloc(s->data, cap);
    if (d == NULL) {
      s->failed = 1;
      return -1;
    }
    memset(d + s->cap, 0, cap - s->cap);
    s->data = d;
    s->cap = cap;
  }
  memcpy(s->data + offset, buffer, sz);
  if (end > s->len) s->len = end;
  return (int64_t)sz;
}

/* The library's message for a failure, kept instead of printed on stderr. */
static void keep_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
  void *ud = NULL;
  if (exr_get_user_data(ctxt, &ud) == EXR_ERR_SUCCESS && ud != NULL) {
    sink *s = (sink *)ud;
    if (s->message[0] == '\0')
      snprintf(s->message, sizeof s->message, "%s", msg ? msg : exr_get_default_error_message(code));
  }
}

static int channel_offset(const char *name)
{
  switch (name[0]) {
  case 'R': return 0;
  case 'G': return 1;
  case 'B': return 2;
  default: return 3; /* A */
  }
}

/* Runs without the OCaml runtime lock: every argument was copied first. */
static exr_result_t write_exr(sink *s, int width, int height, int half, int channels,
                              const float *pixels, const char *record)
{
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  exr_context_t f = NULL;
  exr_encode_pipeline_t enc;
  int part = 0, lines = 1, started = 0;
  exr_result_t rv;
  exr_pixel_type_t type = half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;

  init.user_data = s;
  init.write_fn = sink_write;
  init.error_handler_fn = keep_error;
  memset(&enc, 0, sizeof enc);

  rv = exr_start_write(&f, "image.exr", EXR_WRITE_FILE_DIRECTLY, &init);
  if (rv != EXR_ERR_SUCCESS) return rv;
  rv = exr_add_part(f, "image", EXR_STORAGE_SCANLINE, &part);
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_initialize_required_attr_simple(f, part, width, height, EXR_COMPRESSION_ZIP);
  if (rv == EXR_ERR_SUCCESS && channels == 4)
    rv = exr_add_channel(f, part, "A", type, EXR_PERCEPTUALLY_LINEAR, 1, 1) < 0 ? EXR_ERR_UNKNOWN : EXR_ERR_SUCCESS;
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_channel(f, part, "B", type, EXR_PERCEPTUALLY_LINEAR, 1, 1) < 0 ? EXR_ERR_UNKNOWN : EXR_ERR_SUCCESS;
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_channel(f, part, "G", type, EXR_PERCEPTUALLY_LINEAR, 1, 1) < 0 ? EXR_ERR_UNKNOWN : EXR_ERR_SUCCESS;
  if (rv == EXR_ERR_SUCCESS)
    rv = exr_add_channel(f, part, "R", type, EXR_PERCEPTUALLY_LINEAR, 1, 1) < 0 ? EXR_ERR_UNKNOWN : EXR_ERR_SUCCESS;
  /* Where the image came from: a string attribute of the header, when given. */
  if (rv == EXR_ERR_SUCCESS && record != NULL && record[0] != '\0')
    rv = exr_attr_set_string(f, part, "lancer", record);
  if (rv == EXR_ERR_SUCCESS) rv = exr_write_header(f);
  if (rv == EXR_ERR_SUCCESS) rv = exr_get_scanlines_per_chunk(f, part, &lines);

  for (int y = 0; rv == EXR_ERR_SUCCESS && y < height; y += lines) {
    exr_chunk_info_t chunk;
    rv = exr_write_scanline_chunk_info(f, part, y, &chunk);
    if (rv != EXR_ERR_SUCCESS) break;
    if (!started) {
      rv = exr_encoding_initialize(f, part, &chunk, &enc);
      if (rv != EXR_ERR_SUCCESS) break;
      started = 1;
    } else {
      rv = exr_encoding_update(f, part, &chunk, &enc);
      if (rv != EXR_ERR_SUCCESS) break;
    }
    for (int c = 0; c < enc.channel_count; c++) {
      exr_coding_channel_info_t *ch = &enc.channels[c];
      int k = channel_offset(ch->channel_name);
      ch->encode_from_ptr =
          (const uint8_t *)(pixels + ((size_t)chunk.start_y * width * channels) + k);
      ch->user_pixel_stride = (int32_t)(channels * sizeof(float));
      ch->user_line_stride = (int32_t)((size_t)width * channels * sizeof(float));
      ch->user_data_type = EXR_PIXEL_FLOAT;
      ch->user_bytes_per_element = sizeof(float);
    }
    if (started == 1) {
      rv = exr_encoding_choose_default_routines(f, part, &enc);
      if (rv != EXR_ERR_SUCCESS) break;
      started = 2;
    }
    rv = exr_encoding_run(f, part, &enc);
  }
  if (started) {
    exr_result_t d = exr_encoding_destroy(f, &enc);
    if (rv == EXR_ERR_SUCCESS) rv = d;
  }
  {
    exr_result_t d = exr_finish(&f);
    if (rv == EXR_ERR_SUCCESS) rv = d;
  }
  return rv;
}

value lancer_exr_encode(value vwidth, value vheight, value vhalf, value vrgb, value valpha,
                        value vrecord)
{
  CAMLparam5(vwidth, vheight, vhalf, vrgb, valpha);
  CAMLxparam1(vrecord);
  CAMLlocal1(result);
  int width = Int_val(vwidth), height = Int_val(vheight), half = Bool_val(vhalf);
  int channels = Is_block(valpha) ? 4 : 3;
  size_t n = (size_t)width * (size_t)height;
  float *pixels = malloc(n * channels * sizeof(float));
  sink s;
  exr_result_t rv;

  char *record = NULL;
  memset(&s, 0, sizeof s);
  if (pixels == NULL) caml_raise_out_of_memory();
  if (caml_string_length(vrecord) > 0) {
    /* A copy: the string may move once the runtime is released. */
    record = malloc(caml_string_length(vrecord) + 1);
    if (record == NULL) { free(pixels); caml_raise_out_of_memory(); }
    memcpy(record, String_val(vrecord), caml_string_length(vrecord));
    record[caml_string_length(vrecord)] = '\0';
  }
  /* The doubles as floats, interleaved (R, G, B[, A]) per pixel. */
  for (size_t p = 0; p < n; p++) {
    for (int c = 0; c < 3; c++)
      pixels[p * channels + c] = (float)Double_flat_field(vrgb, 3 * p + c);
    if (channels == 4)
      pixels[p * channels + 3] = (float)Double_flat_field(Field(valpha, 0), p);
  }
  caml_release_runtime_system();
  rv = write_exr(&s, width, height, half, channels, pixels, record);
  caml_acquire_runtime_system();
  free(pixels);
  free(record);
  if (s.failed) {
    free(s.data);
    caml_raise_out_of_memory();
  }
  if (rv != EXR_ERR_SUCCESS) {
    char msg[300];
    snprintf(msg, sizeof msg, "OpenEXR: %s",
             s.message[0] ? s.message : exr_get_default_error_message(rv));
    free(s.data);
    caml_failwith(msg);
  }
  result = caml_alloc_initialized_string(s.len, (const char *)s.data);
  free(s.data);
  CAMLreturn(result);
}

value lancer_exr_encode_byte(value *argv, int argn)
{
  (void)argn;
  return lancer_exr_encode(argv[0], argv[1], argv[2], argv[3], argv[4], argv[5]);
}
