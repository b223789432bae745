/* Test double of the OpenHaptics HD API header (HD/hd.h): only the types, constants and calls
 * graspsim's backend uses, with the names, signatures and values of OpenHaptics 3.x
 * (hdDefines.h, hdDevice.h, hdScheduler.h). Written from the API's documented interface, not
 * copied. The implementation (hd_double.cpp) is scriptable through hd_double.hpp. */
#ifndef GRASPSIM_TEST_HD_DOUBLE_H
#define GRASPSIM_TEST_HD_DOUBLE_H

#include <limits.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define HDAPI
#define HDAPIENTRY
#define HDCALLBACK

typedef unsigned int HDuint;
typedef unsigned char HDboolean;
typedef unsigned long HDulong;
typedef unsigned short HDushort;
typedef int HDint;
typedef float HDfloat;
typedef double HDdouble;
typedef long HDlong;
typedef char HDchar;
typedef unsigned int HDerror;
typedef unsigned int HDenum;
typedef const char* HDstring;
typedef unsigned int HHD;

typedef struct {
  HDerror errorCode;      /* the HD_ error code */
  int internalErrorCode;  /* the device's own code */
  HHD hHD;                /* the device current when it happened */
} HDErrorInfo;

#define HD_TRUE 1
#define HD_FALSE 0

/* Error codes */
#define HD_SUCCESS 0x0000
#define HD_INVALID_ENUM 0x0100
#define HD_INVALID_VALUE 0x0101
#define HD_INVALID_OPERATION 0x0102
#define HD_INVALID_INPUT_TYPE 0x0103
#define HD_BAD_HANDLE 0x0104
#define HD_WARM_MOTORS 0x0200
#define HD_EXCEEDED_MAX_FORCE 0x0201
#define HD_EXCEEDED_MAX_FORCE_IMPULSE 0x0202
#define HD_EXCEEDED_MAX_VELOCITY 0x0203
#define HD_FORCE_ERROR 0x0204
#define HD_DEVICE_FAULT 0x0300
#define HD_DEVICE_ALREADY_INITIATED 0x0301
#define HD_COMM_ERROR 0x0302
#define HD_COMM_CONFIG_ERROR 0x0303
#define HD_TIMER_ERROR 0x0304
#define HD_ILLEGAL_BEGIN 0x0400
#define HD_ILLEGAL_END 0x0401
#define HD_FRAME_ERROR 0x0402
#define HD_INVALID_PRIORITY 0x0500
#define HD_SCHEDULER_FULL 0x0501
#define HD_INVALID_LICENSE 0x0600

#define HD_DEVICE_ERROR(X) (((X).errorCode) != HD_SUCCESS)

/* Get/set parameters */
#define HD_CURRENT_BUTTONS 0x2000
#define HD_CURRENT_POSITION 0x2050
#define HD_CURRENT_GIMBAL_ANGLES 0x2150
#define HD_DEVICE_MODEL_TYPE 0x2501
#define HD_UPDATE_RATE 0x2600
#define HD_NOMINAL_MAX_STIFFNESS 0x2602
#define HD_NOMINAL_MAX_FORCE 0x2603
#define HD_NOMINAL_MAX_CONTINUOUS_FORCE 0x2604
#define HD_CURRENT_FORCE 0x2700

/* Capabilities */
#define HD_FORCE_OUTPUT 0x4000

/* Scheduler */
#define HD_MAX_SCHEDULER_PRIORITY USHRT_MAX
#define HD_MIN_SCHEDULER_PRIORITY 0
#define HD_DEFAULT_SCHEDULER_PRIORITY ((HD_MAX_SCHEDULER_PRIORITY + HD_MIN_SCHEDULER_PRIORITY) / 2)
#define HD_CALLBACK_DONE 0
#define HD_CALLBACK_CONTINUE 1

#define HD_DEVICE_BUTTON_1 (1 << 0)
#define HD_DEVICE_BUTTON_2 (1 << 1)
#define HD_INVALID_HANDLE 0xFFFFFFFF
#define HD_DEFAULT_DEVICE NULL

typedef unsigned int HDCallbackCode;
typedef HDulong HDSchedulerHandle;
typedef HDCallbackCode(HDCALLBACK* HDSchedulerCallback)(void* pUserData);

/* Devices */
HDAPI HHD HDAPIENTRY hdInitDevice(HDstring pConfigName);
HDAPI void HDAPIENTRY hdMakeCurrentDevice(HHD hHD);
HDAPI void HDAPIENTRY hdDisableDevice(HHD hHD);
HDAPI HHD HDAPIENTRY hdGetCurrentDevice(void);
HDAPI void HDAPIENTRY hdBeginFrame(HHD hHD);
HDAPI void HDAPIENTRY hdEndFrame(HHD hHD);
HDAPI HDErrorInfo HDAPIENTRY hdGetError(void);
HDAPI HDstring HDAPIENTRY hdGetErrorString(HDerror errorCode);
HDAPI void HDAPIENTRY hdEnable(HDenum cap);
HDAPI void HDAPIENTRY hdDisable(HDenum cap);
HDAPI void HDAPIENTRY hdGetIntegerv(HDenum pname, HDint* params);
HDAPI void HDAPIENTRY hdGetDoublev(HDenum pname, HDdouble* params);
HDAPI HDstring HDAPIENTRY hdGetString(HDenum pname);
HDAPI void HDAPIENTRY hdSetDoublev(HDenum pname, const HDdouble* params);

/* Scheduler */
HDAPI void HDAPIENTRY hdStartScheduler(void);
HDAPI void HDAPIENTRY hdStopScheduler(void);
HDAPI HDSchedulerHandle HDAPIENTRY hdScheduleAsynchronous(HDSchedulerCallback pCallback,
                                                          void* pUserData, HDushort nPriority);
HDAPI void HDAPIENTRY hdScheduleSynchronous(HDSchedulerCallback pCallback, void* pUserData,
                                            HDushort nPriority);
HDAPI void HDAPIENTRY hdUnschedule(HDSchedulerHandle hHandle);

#ifdef __cplusplus
}
#endif

#endif /* GRASPSIM_TEST_HD_DOUBLE_H */
