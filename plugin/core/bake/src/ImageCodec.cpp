// libpng and libjpeg report errors by longjmp from their error callbacks. Each reader and
// writer below calls setjmp in a function whose C++ objects all live in the caller's frame
// (passed by reference), so a jump destroys nothing and skips no destructor.
#include "TreeLod/ImageCodec.h"

#include <jpeglib.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>

namespace TreeLod
{
    namespace
    {
        constexpr std::size_t kMessageSize = 256;

        bool littleEndianHost()
        {
            const std::uint16_t probe = 1;
            std::uint8_t first = 0;
            std::memcpy(&first, &probe, 1);
            return first == 1;
        }

        /// Into `message` (kMessageSize bytes): why an image of this size is refused.
        void sizeRefusal(char* message, std::uint64_t width, std::uint64_t height, std::uint32_t maxSide,
                         std::uint64_t maxPixels)
        {
            std::snprintf(message, kMessageSize, "image of %llux%llu pixels is larger than the limit (%u per side, %llu pixels)",
                          static_cast<unsigned long long>(width), static_cast<unsigned long long>(height), maxSide,
                          static_cast<unsigned long long>(maxPixels));
        }

        bool beyond(std::uint64_t width, std::uint64_t height, std::uint32_t maxSide, std::uint64_t maxPixels)
        {
            return width > maxSide || height > maxSide || width * height > maxPixels;
        }

        // ---- PNG ------------------------------------------------------------------------------

        struct PngSource
        {
            const std::uint8_t* data;
            std::size_t size;
            std::size_t position;
        };

        void pngError(png_structp png, png_const_charp message)
        {
            std::snprintf(static_cast<char*>(png_get_error_ptr(png)), kMessageSize, "%s", message);
            png_longjmp(png, 1);
        }

        void pngWarning(png_structp, png_const_charp) {}

        void pngRead(png_structp png, png_bytep out, png_size_t count)
        {
            auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
            if (count > source->size - source->position)
                png_error(png, "truncated data");
            std::memcpy(out, source->data + source->position, count);
            source->position += count;
        }

        void pngWrite(png_structp png, png_bytep data, png_size_t count)
        {
            auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
            if (out->max_size() - out->size() < count)
                png_error(png, "output too large");
            try
            {
                out->insert(out->end(), data, data + count);
            }
            catch (const std::bad_alloc&)
            {
                png_error(png, "out of memory");
            }
        }

        void pngFlush(png_structp) {}

        /// `raw` receives the rows as libpng delivers them (16-bit samples in host order).
        bool readPng(const std::uint8_t* data, std::size_t size, std::uint32_t maxSide, std::uint64_t maxPixels,
                     DecodedImage& out, std::vector<std::uint8_t>& raw, std::vector<png_bytep>& rows, char* message)
        {
            png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, message, pngError, pngWarning);
            png_infop info = png ? png_create_info_struct(png) : nullptr;
            if (!info)
            {
                png_destroy_read_struct(&png, nullptr, nullptr);
                std::snprintf(message, kMessageSize, "out of memory");
                return false;
            }
            PngSource source{data, size, 0};
            if (setjmp(png_jmpbuf(png)))
            {
                png_destroy_read_struct(&png, &info, nullptr);
                return false;
            }
            png_set_read_fn(png, &source, pngRead);
            png_set_user_limits(png, 0x7fffffff, 0x7fffffff); // the limit below, with its own message
            png_read_info(png, info);
            const png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
            if (beyond(width, height, maxSide, maxPixels))
            {
                sizeRefusal(message, width, height, maxSide, maxPixels);
                png_longjmp(png, 1);
            }
            const int colourType = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
            if (colourType == PNG_COLOR_TYPE_PALETTE)
                png_set_palette_to_rgb(png);
            if (colourType == PNG_COLOR_TYPE_GRAY && depth < 8)
                png_set_expand_gray_1_2_4_to_8(png);
            if (png_get_valid(png, info, PNG_INFO_tRNS))
                png_set_tRNS_to_alpha(png);
            if (depth == 16 && littleEndianHost())
                png_set_swap(png);
            png_set_interlace_handling(png);
            png_read_update_info(png, info);

            out.width = int(width);
            out.height = int(height);
            out.channels = png_get_channels(png, info);
            out.bits = png_get_bit_depth(png, info) == 16 ? 16 : 8;
            const std::size_t rowBytes = png_get_rowbytes(png, info);
            raw.resize(rowBytes * height);
            rows.resize(height);
            for (png_uint_32 y = 0; y < height; ++y)
                rows[y] = raw.data() + rowBytes * y;
            png_read_image(png, rows.data());
            png_read_end(png, nullptr);
            png_destroy_read_struct(&png, &info, nullptr);
            return true;
        }

        bool writePng(const std::uint8_t* samples, int width, int height, int channels, int level,
                      std::vector<std::uint8_t>& out, std::vector<png_bytep>& rows, char* message)
        {
            png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, message, pngError, pngWarning);
            png_infop info = png ? png_create_info_struct(png) : nullptr;
            if (!info)
            {
                png_destroy_write_struct(&png, nullptr);
                std::snprintf(message, kMessageSize, "out of memory");
                return false;
            }
            if (setjmp(png_jmpbuf(png)))
            {
                png_destroy_write_struct(&png, &info);
                return false;
            }
            static const int colourTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                              PNG_COLOR_TYPE_RGB_ALPHA};
            png_set_write_fn(png, &out, pngWrite, pngFlush);
            png_set_compression_level(png, level);
            png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, colourTypes[channels - 1],
                         PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
            png_write_info(png, info);
            const std::size_t rowBytes = std::size_t(width) * std::size_t(channels);
            rows.resize(std::size_t(height));
            for (int y = 0; y < height; ++y)
                rows[std::size_t(y)] = const_cast<png_bytep>(samples + rowBytes * std::size_t(y));
            png_write_image(png, rows.data());
            png_write_end(png, nullptr);
            png_destroy_write_struct(&png, &info);
            return true;
        }

        // ---- JPEG -----------------------------------------------------------------------------

        struct JpegErrors
        {
            jpeg_error_mgr manager;
            std::jmp_buf jump;
            char message[kMessageSize];
        };

        void jpegErrorExit(j_common_ptr info)
        {
            auto* errors = reinterpret_cast<JpegErrors*>(info->err);
            char text[JMSG_LENGTH_MAX];
            (*info->err->format_message)(info, text);
            std::snprintf(errors->message, kMessageSize, "%s", text);
            std::longjmp(errors->jump, 1);
        }

        void jpegSilent(j_common_ptr) {}

        bool readJpeg(const std::uint8_t* data, std::size_t size, std::uint32_t maxSide, std::uint64_t maxPixels,
                      DecodedImage& out, std::vector<std::uint8_t>& raw, JpegErrors& errors)
        {
            jpeg_decompress_struct info;
            info.err = jpeg_std_error(&errors.manager);
            errors.manager.error_exit = jpegErrorExit;
            errors.manager.output_message = jpegSilent; // warnings (corrupt-data recoveries) are not errors
            if (setjmp(errors.jump))
            {
                jpeg_destroy_decompress(&info);
                return false;
            }
            jpeg_create_decompress(&info);
            jpeg_mem_src(&info, data, static_cast<unsigned long>(size));
            jpeg_read_header(&info, TRUE);
            if (beyond(info.image_width, info.image_height, maxSide, maxPixels))
            {
                sizeRefusal(errors.message, info.image_width, info.image_height, maxSide, maxPixels);
                std::longjmp(errors.jump, 1);
            }
            const bool cmyk = info.jpeg_color_space == JCS_CMYK || info.jpeg_color_space == JCS_YCCK;
            info.out_color_space = cmyk ? JCS_CMYK : info.num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
            jpeg_start_decompress(&info);
            const std::size_t rowBytes = std::size_t(info.output_width) * std::size_t(info.output_components);
            raw.resize(rowBytes * info.output_height);
            while (info.output_scanline < info.output_height)
            {
                JSAMPROW row = raw.data() + rowBytes * info.output_scanline;
                jpeg_read_scanlines(&info, &row, 1);
            }
            out.width = int(info.output_width);
            out.height = int(info.output_height);
            out.channels = cmyk ? 4 : info.output_components;
            out.bits = 8;
            const bool inverted = info.saw_Adobe_marker; // Adobe CMYK stores ink as 255 - amount
            jpeg_finish_decompress(&info);
            jpeg_destroy_decompress(&info);
            if (cmyk)
            {
                // CMYK to RGB: each channel is (1 - ink) * (1 - black).
                const std::size_t pixels = std::size_t(out.width) * std::size_t(out.height);
                for (std::size_t i = 0; i < pixels; ++i)
                {
                    std::uint8_t* p = &raw[i * 4];
                    const unsigned k = inverted ? p[3] : 255u - p[3];
                    for (int c = 0; c < 3; ++c)
                        raw[i * 3 + std::size_t(c)] = std::uint8_t(((inverted ? p[c] : 255u - p[c]) * k + 127u) / 255u);
                }
                raw.resize(pixels * 3);
                out.channels = 3;
            }
            return true;
        }
    }

    ImageFormat sniffImageFormat(const std::uint8_t* data, std::size_t size)
    {
        static const std::uint8_t pngSignature[8] = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
        if (size >= 8 && std::memcmp(data, pngSignature, 8) == 0)
            return ImageFormat::Png;
        if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF)
            return ImageFormat::Jpeg;
        return ImageFormat::Unknown;
    }

    Result<DecodedImage> decodeImage(const std::uint8_t* data, std::size_t size, std::uint32_t maxSide,
                                     std::uint64_t maxPixels)
    {
        const ImageFormat format = sniffImageFormat(data, size);
        if (format == ImageFormat::Unknown)
            return fail("", "", "not an image or unsupported format (neither PNG nor JPEG)");
        DecodedImage image;
        std::vector<std::uint8_t> raw;
        bool decoded = false;
        std::string why;
        if (format == ImageFormat::Png)
        {
            std::vector<png_bytep> rows;
            char message[kMessageSize] = {};
            decoded = readPng(data, size, maxSide, maxPixels, image, raw, rows, message);
            why = message;
        }
        else
        {
            JpegErrors errors{};
            decoded = readJpeg(data, size, maxSide, maxPixels, image, raw, errors);
            why = errors.message;
        }
        const char* name = format == ImageFormat::Png ? "PNG" : "JPEG";
        if (!decoded)
            return fail("", "", std::string("cannot decode ") + name + ": " + why);
        if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4)
            return fail("", "", std::string("unusable ") + name + " layout " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " with " + std::to_string(image.channels) +
                                    " channels");

        const std::size_t count = std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels);
        image.samples.resize(count);
        if (image.bits == 16)
            std::memcpy(image.samples.data(), raw.data(), count * 2);
        else
            for (std::size_t i = 0; i < count; ++i)
                image.samples[i] = raw[i];
        return image;
    }

    Result<std::vector<std::uint8_t>> encodePng(const std::uint8_t* samples, int width, int height, int channels,
                                                int level)
    {
        if (width <= 0 || height <= 0 || channels < 1 || channels > 4)
            return fail("", "", "cannot encode a " + std::to_string(width) + "x" + std::to_string(height) +
                                    " image with " + std::to_string(channels) + " channels as PNG");
        std::vector<std::uint8_t> bytes;
        std::vector<png_bytep> rows;
        char message[kMessageSize] = {};
        if (!writePng(samples, width, height, channels, level, bytes, rows, message))
            return fail("", "", std::string("PNG encoding failed: ") + message);
        return bytes;
    }
}
